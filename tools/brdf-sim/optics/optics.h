// The rig's optics as brdf-sim models them: what the PR-650 reads right now. A tungsten lamp lights
// whatever is mounted on the holder (the virtual sample, the white standard, or the dark shutter);
// the holder's live pose (from the stage simulator) sets the incident and viewing directions (or,
// for the sample-fixed method, the directions where the operator placed lamp and detector, set on
// the control unit: registers 29–33 of stage/control_map.h); the
// detector adds noise and picks an integration time. This is the MeterBackend behind the PR-650
// endpoint, and TrueBrdf is the ground truth that tests compare the daemon's results against.
// The sample is a material (core/material): a file named by --material, or a built-in one.
//
// Radiance the meter sees (W·m⁻²·sr⁻¹·nm⁻¹), with E(λ) the lamp's irradiance at normal incidence:
//   sample: E(λ) · f(θi, φi, θo, φo, λ) · cos θi + ambient
//   white:  E(λ) · ρw / π · cos θi + ambient          (Lambertian, ρw = 0.99)
//   dark:   ambient                                   (the shutter is closed)
// A lamp or detector below the mounted surface contributes nothing but the ambient level. So the
// daemon's BRDF, (I − D) / (I0 − D) · ρw / π · cos θi,ref / cos θi, reproduces f within the noise.
// The rig's known errors (optics/errors.h, all off by default) modify this: E drifts, ρw is off by
// a factor drawn once, λ is shifted, the pose the optics use is jittered, stray light adds
// stray_light · E(λ) / π to sample and white readings, and a gain multiplies a whole measurement.
#pragma once

#include <cstdint>
#include <memory>
#include <mutex>
#include <random>
#include <string>
#include <vector>

#include "core/analytic_brdf.h"  // the built-in samples
#include "core/material/material.h"
#include "core/pose.h"
#include "core/wavelength_grid.h"
#include "tools/brdf-sim/optics/detector.h"
#include "tools/brdf-sim/optics/errors.h"
#include "tools/brdf-sim/optics/lamp.h"
#include "tools/brdf-sim/sim_shared.h"

namespace brdf::sim {

struct OpticsConfig {
  LampConfig lamp;
  DetectorConfig detector;
  // The white standard's reflectance (the paper's RS-3: 0.99 ± 0.01), spectrally flat.
  double white_reflectance = 0.99;
  // Stray light and detector dark signal, spectrally flat (W·m⁻²·sr⁻¹·nm⁻¹). Seen in every reading;
  // alone with the shutter closed. Low enough that a dark reading earns quality 10 or 18.
  double ambient_radiance = 5e-6;
  // The virtual sample: AnalyticBrdf::PaintLike(), Brushed() when anisotropic, Glossy() when
  // glossy (not both), as materials (core/material/builtin_samples.h); or the material file at
  // material_path (--material), which optics/material.h reads into `material`.
  bool anisotropic = false;
  bool glossy = false;
  std::string material_path;
  std::shared_ptr<const material::Material> material;  // null: the built-in sample
  // Seeds the noise: the same seed and the same sequence of measurements give the same readings.
  std::uint64_t seed = 1;
  // Standard deviations scale by this (0 = noiseless, for tests that want exact values).
  double noise_scale = 1.0;
  // The meter's wavelength grid: the PR-650's 101 bands; a PR-670's 201 (2 nm), a CS-2000's 401
  // (1 nm). Every band sees the same physics; only the sampling differs.
  WavelengthGrid grid = WavelengthGrid::Pr650();
  // The rig's known errors beyond the detector's noise (optics/errors.h); all off by default.
  ErrorSources errors;
};

// The built-in virtual sample as a material, and its name ("paint-like", "brushed (anisotropic)",
// "glossy").
material::Material SampleMaterial(bool anisotropic, bool glossy = false);
const char* SampleName(bool anisotropic, bool glossy);
// The sample `config` mounts: its material if set, else the built-in one.
material::Material MountedSample(const OpticsConfig& config);

// Ground truth: the virtual sample's BRDF (sr⁻¹) on the PR-650 grid (380–780 nm every 4 nm) for
// directions in the sample frame (degrees). Zero where either direction is below the surface.
std::vector<double> TrueBrdf(const Directions& directions, bool anisotropic = false,
                             bool glossy = false);

class RigOptics final : public MeterBackend {
 public:
  // `stage` and `control` must outlive this object.
  RigOptics(const StagePoseSource& stage, SimControl& control, OpticsConfig config = {});

  // One measurement of whatever is mounted, at the stage's live pose. Applies an injected quality
  // code (SimControl's SerialFaults.quality_code for the next quality_count measurements, counted
  // down here, so the PR-650 endpoint does not apply it again). Thread-safe.
  SimMeasurement Measure(const MeterSetup& setup) override;

  // The noiseless radiance the meter would see for `target` at `pose`, on the meter's grid (with
  // the lamp's present drift, the white error, the wavelength shift and stray light; without
  // pose jitter and gain, which are drawn per measurement).
  std::vector<double> ExpectedRadiance(MountedTarget target, const Pose& pose) const;
  // The same for lamp and detector at `directions` (placed by hand: the sample-fixed method, where
  // SimControl::by_hand() makes Measure use SimControl::placed() instead of the holder's pose).
  std::vector<double> ExpectedRadianceAt(MountedTarget target, const Directions& directions) const;

  // The virtual sample's BRDF (sr⁻¹) for directions in the sample frame.
  std::vector<double> TrueBrdf(const Directions& directions) const;

  const OpticsConfig& config() const { return config_; }
  const Lamp& lamp() const { return lamp_; }
  const Detector& detector() const { return detector_; }
  const WavelengthGrid& Grid() const { return config_.grid; }
  const RigErrors& errors() const { return errors_; }
  const material::Material& sample() const { return sample_; }

 private:
  const StagePoseSource& stage_;
  SimControl& control_;
  const OpticsConfig config_;
  const Lamp lamp_;
  const Detector detector_;
  const material::Material sample_;
  RigErrors errors_;
  // The wavelengths the meter's bands really measure: the grid moved by the wavelength shift.
  const WavelengthGrid measured_grid_;
  const std::vector<double> lamp_spectrum_;  // E(λ) on measured_grid_

  std::mutex noise_mu_;  // guards rng_
  std::mt19937_64 rng_;
};

}  // namespace brdf::sim
