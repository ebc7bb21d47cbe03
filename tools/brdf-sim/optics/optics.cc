#include "tools/brdf-sim/optics/optics.h"

#include <spdlog/spdlog.h>

#include <algorithm>
#include <cmath>
#include <numbers>

#include "core/geometry.h"
#include "core/material/builtin_samples.h"

namespace brdf::sim {
namespace {

constexpr double kDegToRad = std::numbers::pi / 180.0;

// cos θ for a direction in the sample frame, 0 when it is below the surface (θ > 90°) or not a
// number: light from behind the surface does not reach it.
double CosAbove(double theta_deg) {
  if (!std::isfinite(theta_deg)) return 0.0;
  return std::max(0.0, std::cos(theta_deg * kDegToRad));
}

}  // namespace

material::Material SampleMaterial(bool anisotropic, bool glossy) {
  if (anisotropic) return material::BrushedMaterial();
  return glossy ? material::GlossyMaterial() : material::PaintMaterial();
}

const char* SampleName(bool anisotropic, bool glossy) {
  if (anisotropic) return "brushed (anisotropic)";
  return glossy ? "glossy" : "paint-like";
}

material::Material MountedSample(const OpticsConfig& config) {
  return config.material ? *config.material : SampleMaterial(config.anisotropic, config.glossy);
}

std::vector<double> TrueBrdf(const Directions& directions, bool anisotropic, bool glossy) {
  return SampleMaterial(anisotropic, glossy).EvaluateSpectrum(directions, WavelengthGrid::Pr650());
}

namespace {
WavelengthGrid Shifted(WavelengthGrid grid, double shift_nm) {
  grid.start_nm += shift_nm;
  return grid;
}
}  // namespace

RigOptics::RigOptics(const StagePoseSource& stage, SimControl& control, OpticsConfig config)
    : stage_(stage),
      control_(control),
      config_(config),
      lamp_(config.lamp),
      detector_(config.detector),
      sample_(MountedSample(config)),
      errors_(config.errors, config.seed),
      measured_grid_(Shifted(Grid(), errors_.wavelength_shift_nm())),
      lamp_spectrum_(lamp_.Spectrum(measured_grid_)),
      rng_(config.seed) {}

std::vector<double> RigOptics::TrueBrdf(const Directions& directions) const {
  return sample_.EvaluateSpectrum(directions, Grid());
}

std::vector<double> RigOptics::ExpectedRadiance(MountedTarget target, const Pose& pose) const {
  return ExpectedRadianceAt(target, PoseToDirections(pose));
}

std::vector<double> RigOptics::ExpectedRadianceAt(MountedTarget target, const Directions& d) const {
  const WavelengthGrid& grid = measured_grid_;
  std::vector<double> out(grid.count, config_.ambient_radiance);
  if (target == MountedTarget::kDark) return out;

  // Without drift the factor is exactly 1 and leaves every product as it was.
  const double lamp = errors_.LampFactor();
  if (const double stray = errors_.sources().stray_light; stray > 0) {
    for (std::size_t k = 0; k < grid.count; ++k) {
      out[k] += stray * lamp_spectrum_[k] / std::numbers::pi * lamp;
    }
  }
  const double cos_i = CosAbove(d.theta_i);
  // The detector behind the surface sees only the holder's back: ambient (and stray) light.
  if (cos_i <= 0.0 || CosAbove(d.theta_o) <= 0.0) return out;

  if (target == MountedTarget::kWhite) {
    const double lambertian = config_.white_reflectance * errors_.white_factor() / std::numbers::pi;
    for (std::size_t k = 0; k < grid.count; ++k) {
      out[k] += lamp_spectrum_[k] * lambertian * cos_i * lamp;
    }
    return out;
  }
  const std::vector<double> f = sample_.EvaluateSpectrum(d, grid);
  for (std::size_t k = 0; k < grid.count; ++k) out[k] += lamp_spectrum_[k] * f[k] * cos_i * lamp;
  return out;
}

SimMeasurement RigOptics::Measure(const MeterSetup& setup) {
  const MountedTarget target = control_.mounted();
  // Placed by hand (the sample-fixed method): where the operator put lamp and detector, as is.
  const Directions directions = control_.by_hand()
                                    ? control_.placed()
                                    : PoseToDirections(errors_.TruePose(stage_.LivePose()));
  std::vector<double> expected = ExpectedRadianceAt(target, directions);
  if (const double gain = errors_.NextGain(); gain != 1.0) {
    for (double& e : expected) e = std::max(0.0, e * gain);
  }

  const double peak = *std::max_element(expected.begin(), expected.end());
  const Exposure exposure = detector_.ChooseExposure(peak, setup);
  const int averages = std::max(setup.averages, 1);
  const double saturation = detector_.SaturationRadiance(exposure.integration_ms);

  SimMeasurement m;
  m.integration_ms = exposure.integration_ms;
  m.quality_code = exposure.quality_code;
  m.duration_s = detector_.DurationSeconds(exposure.integration_ms, averages);
  m.radiance.resize(expected.size());
  {
    std::lock_guard lock(noise_mu_);
    std::normal_distribution<double> unit(0.0, 1.0);
    for (std::size_t k = 0; k < expected.size(); ++k) {
      const double sigma = config_.noise_scale *
                           detector_.NoiseSigma(expected[k], exposure.integration_ms, averages);
      // The meter reports no negative radiance, and an overloaded band reads full scale.
      m.radiance[k] = std::clamp(expected[k] + sigma * unit(rng_), 0.0, saturation);
    }
  }
  errors_.AdvanceLamp(m.duration_s);
  const double step = Grid().step_nm;
  for (double r : m.radiance) m.integrated += r * step;
  // What the meter chose, for timing the rig (bench/daemon/estimate.sh reads these lines).
  static constexpr const char* kTargetNames[] = {"sample", "white", "dark"};
  spdlog::debug("measure {}: integration {} ms x {}, {:.3f} s simulated, quality {}",
                kTargetNames[static_cast<int>(target)], m.integration_ms, averages, m.duration_s,
                m.quality_code);

  return m;
}

}  // namespace brdf::sim
