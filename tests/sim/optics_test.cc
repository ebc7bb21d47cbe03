// The optical model behind the simulated PR-650: what the meter reads for the sample, the white
// standard and the dark shutter at a pose, and how the detector's light level shows in the
// integration time and the quality code.
#include "tools/brdf-sim/optics/optics.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <numbers>
#include <vector>

#include "core/geometry.h"
#include "tools/brdf-sim/optics/manual_detector.h"

namespace brdf::sim {
namespace {

constexpr double kPi = std::numbers::pi;

// Stands in for the stage simulator: the holder sits at a pose the test sets.
class FixedStage final : public StagePoseSource {
 public:
  Pose LivePose() const override { return pose; }
  Pose pose;
};

// Planck's law, written independently of the lamp model: spectral irradiance at normal incidence
// with the configured value at 560 nm.
double PlanckIrradiance(const LampConfig& lamp, double nm) {
  const double h = 6.62607015e-34, c = 299792458.0, k = 1.380649e-23;
  auto b = [&](double wl_nm) {
    const double wl = wl_nm * 1e-9;
    return 2 * h * c * c / std::pow(wl, 5) /
           (std::exp(h * c / (wl * k * lamp.color_temperature_k)) - 1);
  };
  return lamp.irradiance_at_560nm * b(nm) / b(560.0);
}

double CosDeg(double deg) {
  return std::cos(deg * kPi / 180.0);
}

struct Rig {
  explicit Rig(OpticsConfig config = {}) : optics(stage, control, config) {}
  SimMeasurement MeasureAt(MountedTarget target, const Pose& pose, MeterSetup setup = {}) {
    control.set_mounted(target);
    stage.pose = pose;
    return optics.Measure(setup);
  }
  FixedStage stage;
  SimControl control;
  RigOptics optics;
};

TEST(RigOpticsTest, WhiteAtNormalIncidenceReadsLampTimesReflectanceOverPi) {
  Rig rig;
  const SimMeasurement m = rig.MeasureAt(MountedTarget::kWhite, Pose{0, 0, 0, 0});
  const OpticsConfig& cfg = rig.optics.config();
  const WavelengthGrid grid = WavelengthGrid::Pr650();
  ASSERT_EQ(m.radiance.size(), grid.count);
  EXPECT_EQ(m.quality_code, 0);
  for (std::size_t k = 0; k < grid.count; ++k) {
    const double expected =
        PlanckIrradiance(cfg.lamp, grid.at(k)) * 0.99 / kPi + cfg.ambient_radiance;
    const double sigma = rig.optics.detector().NoiseSigma(expected, m.integration_ms, 1);
    EXPECT_NEAR(m.radiance[k], expected, 5 * sigma) << grid.at(k) << " nm";
    EXPECT_LT(sigma, 0.05 * expected) << "noise should be small for the white standard";
  }
}

TEST(RigOpticsTest, NoiselessWhiteFollowsCosineOfIncidence) {
  OpticsConfig cfg;
  cfg.noise_scale = 0;
  Rig rig(cfg);
  const WavelengthGrid grid = WavelengthGrid::Pr650();
  // α = 0, δ = β: the lamp at θi = β, the detector on the normal.
  for (double beta : {0.0, 30.0, 60.0, 80.0}) {
    const SimMeasurement m = rig.MeasureAt(MountedTarget::kWhite, Pose{0, beta, 0, beta});
    for (std::size_t k = 0; k < grid.count; k += 10) {
      const double expected =
          PlanckIrradiance(cfg.lamp, grid.at(k)) * 0.99 / kPi * CosDeg(beta) + cfg.ambient_radiance;
      EXPECT_NEAR(m.radiance[k], expected, 1e-9 * expected) << "beta " << beta;
    }
  }
}

// The daemon's reduction: (I − D) / (I0 − D) · ρw/π · cos θi,ref / cos θi.
std::vector<double> ReducedBrdf(const SimMeasurement& sample, const SimMeasurement& white,
                                const SimMeasurement& dark, double theta_i_ref, double theta_i) {
  std::vector<double> f(sample.radiance.size());
  for (std::size_t k = 0; k < f.size(); ++k) {
    f[k] = (sample.radiance[k] - dark.radiance[k]) / (white.radiance[k] - dark.radiance[k]) * 0.99 /
           kPi * CosDeg(theta_i_ref) / CosDeg(theta_i);
  }
  return f;
}

void ExpectReductionReproducesTruth(bool anisotropic, const std::vector<Pose>& poses) {
  OpticsConfig cfg;
  cfg.anisotropic = anisotropic;
  cfg.seed = 11;
  Rig rig(cfg);
  const Detector& det = rig.optics.detector();
  const Pose reference{0, 20, 0, 0};  // white taken at θi,ref = 20°, not at normal incidence
  const double theta_i_ref = PoseToDirections(reference).theta_i;
  const SimMeasurement dark = rig.MeasureAt(MountedTarget::kDark, reference);
  const SimMeasurement white = rig.MeasureAt(MountedTarget::kWhite, reference);
  for (const Pose& pose : poses) {
    const Directions d = PoseToDirections(pose);
    const SimMeasurement sample = rig.MeasureAt(MountedTarget::kSample, pose);
    const std::vector<double> truth = TrueBrdf(d, anisotropic);
    ASSERT_LT(d.theta_i, 90) << "test pose must light the sample";
    ASSERT_LT(d.theta_o, 90) << "test pose must see the sample";
    const std::vector<double> f = ReducedBrdf(sample, white, dark, theta_i_ref, d.theta_i);
    ASSERT_EQ(truth.size(), f.size());
    for (std::size_t k = 0; k < f.size(); ++k) {
      // Propagated noise of the three readings (relative errors add in quadrature).
      const double s = sample.radiance[k] - dark.radiance[k];
      const double w = white.radiance[k] - dark.radiance[k];
      const double sd = det.NoiseSigma(dark.radiance[k], dark.integration_ms, 1);
      const double ss =
          std::hypot(det.NoiseSigma(sample.radiance[k], sample.integration_ms, 1), sd);
      const double sw = std::hypot(det.NoiseSigma(white.radiance[k], white.integration_ms, 1), sd);
      const double rel = std::hypot(ss / s, sw / w);
      EXPECT_NEAR(f[k], truth[k], 5 * rel * truth[k])
          << "pose (" << pose.alpha << ", " << pose.beta << ", " << pose.gamma << ", " << pose.delta
          << ") band " << k;
    }
  }
}

TEST(RigOpticsTest, ReducedReadingsReproduceTrueBrdf) {
  ExpectReductionReproducesTruth(false, {
                                            Pose{20, 30, 0, 60},
                                            Pose{0, 30, 0, 60},  // specular: normal bisects
                                            Pose{40, 30, 0, 100},
                                            Pose{60, 10, 0, 33.75},
                                        });
}

TEST(RigOpticsTest, ReducedReadingsReproduceTrueBrdfOfAnisotropicSample) {
  ExpectReductionReproducesTruth(true, {Pose{0, 30, 0, 60}, Pose{0, 30, 45, 60},
                                        Pose{20, 10, 90, 45}, Pose{30, 50, -60, 120}});
}

TEST(RigOpticsTest, AnisotropicSampleDependsOnDialButIsotropicDoesNot) {
  OpticsConfig cfg;
  cfg.noise_scale = 0;
  Rig iso(cfg);
  cfg.anisotropic = true;
  Rig aniso(cfg);
  const Pose a{10, 30, 0, 60}, b{10, 30, 60, 60};
  const auto iso_a = iso.optics.ExpectedRadiance(MountedTarget::kSample, a);
  const auto iso_b = iso.optics.ExpectedRadiance(MountedTarget::kSample, b);
  const auto an_a = aniso.optics.ExpectedRadiance(MountedTarget::kSample, a);
  const auto an_b = aniso.optics.ExpectedRadiance(MountedTarget::kSample, b);
  EXPECT_NEAR(iso_a[50], iso_b[50], 1e-12 * iso_a[50]);
  EXPECT_GT(std::abs(an_a[50] - an_b[50]), 0.01 * an_a[50]);
}

TEST(RigOpticsTest, DarkReadsAmbientLevel) {
  Rig rig;
  const double ambient = rig.optics.config().ambient_radiance;
  ASSERT_GT(ambient, 0);
  const SimMeasurement m = rig.MeasureAt(MountedTarget::kDark, Pose{30, 20, 0, 45});
  const double sigma = rig.optics.detector().NoiseSigma(ambient, m.integration_ms, 1);
  double mean = 0;
  for (double r : m.radiance) {
    EXPECT_NEAR(r, ambient, 5 * sigma);
    mean += r / static_cast<double>(m.radiance.size());
  }
  EXPECT_NEAR(mean, ambient, 5 * sigma / std::sqrt(static_cast<double>(m.radiance.size())));
}

TEST(RigOpticsTest, SampleOrWhiteFacingAwayReadsOnlyAmbient) {
  OpticsConfig cfg;
  cfg.noise_scale = 0;
  Rig rig(cfg);
  // β = 120: the lamp is behind the surface. β = 0, δ = 150, α = 0: detector behind it.
  for (const Pose& pose : {Pose{0, 120, 0, 120}, Pose{0, -30, 0, 150}}) {
    for (MountedTarget t : {MountedTarget::kSample, MountedTarget::kWhite}) {
      for (double r : rig.optics.ExpectedRadiance(t, pose)) EXPECT_EQ(r, cfg.ambient_radiance);
    }
  }
}

TEST(RigOpticsTest, OverloadWithFixedIntegrationTooLongForTheLight) {
  Rig rig;
  const DetectorConfig& det = rig.optics.detector().config();
  const Pose normal{0, 0, 0, 0};
  const auto expected = rig.optics.ExpectedRadiance(MountedTarget::kWhite, normal);
  const double peak = *std::max_element(expected.begin(), expected.end());
  // Twice the time that fills the detector.
  const int overload_ms = static_cast<int>(2 * det.full_scale / peak * 1000);
  ASSERT_GE(overload_ms, det.min_integration_ms);
  ASSERT_LE(overload_ms, det.max_integration_ms);
  EXPECT_EQ(rig.MeasureAt(MountedTarget::kWhite, normal, {overload_ms, 1}).quality_code, 19);
  // Half the filling time is fine, and so is adaptive.
  EXPECT_EQ(rig.MeasureAt(MountedTarget::kWhite, normal, {overload_ms / 4, 1}).quality_code, 0);
  EXPECT_EQ(rig.MeasureAt(MountedTarget::kWhite, normal, {0, 1}).quality_code, 0);
}

TEST(RigOpticsTest, LowAndWeakLightWithFixedIntegration) {
  Rig rig;
  const DetectorConfig& det = rig.optics.detector().config();
  // The white standard lit at grazing incidence: dim.
  const Pose grazing{0, 85, 0, 85};
  const auto expected = rig.optics.ExpectedRadiance(MountedTarget::kWhite, grazing);
  const double peak = *std::max_element(expected.begin(), expected.end());
  const double low_fill = (det.weak_fill + det.low_light_fill) / 2;  // between the thresholds
  const int low_ms = static_cast<int>(std::lround(low_fill * det.full_scale / peak * 1000));
  ASSERT_GE(low_ms, det.min_integration_ms);
  EXPECT_EQ(rig.MeasureAt(MountedTarget::kWhite, grazing, {low_ms, 1}).quality_code, 18);
  // Ten times longer is plenty of light; adaptive finds enough too.
  EXPECT_EQ(rig.MeasureAt(MountedTarget::kWhite, grazing, {10 * low_ms, 1}).quality_code, 0);
  EXPECT_EQ(rig.MeasureAt(MountedTarget::kWhite, grazing, {0, 1}).quality_code, 0);

  // Dark: even the longest integration does not reach the weak threshold.
  const double ambient = rig.optics.config().ambient_radiance;
  ASSERT_LT(ambient * det.max_integration_ms / 1000 / det.full_scale, det.weak_fill);
  EXPECT_EQ(rig.MeasureAt(MountedTarget::kDark, grazing, {100, 1}).quality_code, 10);
  EXPECT_EQ(rig.MeasureAt(MountedTarget::kDark, grazing, {0, 1}).quality_code, 10);
}

TEST(RigOpticsTest, AdaptiveIntegrationIsShortForBrightAndLongForDim) {
  Rig rig;
  const DetectorConfig& det = rig.optics.detector().config();
  const SimMeasurement white = rig.MeasureAt(MountedTarget::kWhite, Pose{0, 0, 0, 0});
  const SimMeasurement white_tilted = rig.MeasureAt(MountedTarget::kWhite, Pose{0, 60, 0, 60});
  const SimMeasurement sample = rig.MeasureAt(MountedTarget::kSample, Pose{70, 0, 0, 30});
  const SimMeasurement dark = rig.MeasureAt(MountedTarget::kDark, Pose{0, 0, 0, 0});
  EXPECT_LT(white.integration_ms, white_tilted.integration_ms);
  EXPECT_LT(white_tilted.integration_ms, sample.integration_ms);
  EXPECT_EQ(dark.integration_ms, det.max_integration_ms);
  for (const SimMeasurement* m : {&white, &white_tilted, &sample}) {
    EXPECT_GE(m->integration_ms, det.min_integration_ms);
    EXPECT_LE(m->integration_ms, det.max_integration_ms);
    EXPECT_EQ(m->quality_code, 0);
    // The brightest band lands near the target fill.
    const double peak = *std::max_element(m->radiance.begin(), m->radiance.end());
    EXPECT_NEAR(peak * m->integration_ms / 1000 / det.full_scale, det.adaptive_fill, 0.05);
  }
  // The white at normal incidence halves its time when the lamp doubles.
  OpticsConfig bright;
  bright.lamp.irradiance_at_560nm *= 2;
  Rig bright_rig(bright);
  const SimMeasurement w2 = bright_rig.MeasureAt(MountedTarget::kWhite, Pose{0, 0, 0, 0});
  EXPECT_NEAR(w2.integration_ms, white.integration_ms / 2.0, 1.0);
}

TEST(RigOpticsTest, AdaptiveCannotGoBelowShortestIntegration) {
  OpticsConfig blinding;
  blinding.lamp.irradiance_at_560nm *= 1000;
  Rig rig(blinding);
  const SimMeasurement m = rig.MeasureAt(MountedTarget::kWhite, Pose{0, 0, 0, 0});
  EXPECT_EQ(m.integration_ms, rig.optics.detector().config().min_integration_ms);
  EXPECT_EQ(m.quality_code, 19);
}

TEST(RigOpticsTest, DurationIsIntegrationTimesAveragesPlusOverhead) {
  Rig rig;
  const double overhead = rig.optics.detector().config().overhead_s;
  const SimMeasurement one = rig.MeasureAt(MountedTarget::kWhite, Pose{0, 0, 0, 0}, {500, 1});
  const SimMeasurement five = rig.MeasureAt(MountedTarget::kWhite, Pose{0, 0, 0, 0}, {200, 5});
  EXPECT_DOUBLE_EQ(one.duration_s, 0.5 + overhead);
  EXPECT_DOUBLE_EQ(five.duration_s, 1.0 + overhead);
  const SimMeasurement adaptive = rig.MeasureAt(MountedTarget::kSample, Pose{30, 0, 0, 45});
  EXPECT_DOUBLE_EQ(adaptive.duration_s, adaptive.integration_ms / 1000.0 + overhead);
}

TEST(RigOpticsTest, AveragingReducesNoise) {
  OpticsConfig cfg;
  Rig rig(cfg);
  const Pose pose{0, 0, 0, 0};
  const auto expected = rig.optics.ExpectedRadiance(MountedTarget::kWhite, pose);
  auto rms_error = [&](int averages) {
    double sum = 0;
    for (int rep = 0; rep < 20; ++rep) {
      const SimMeasurement m = rig.MeasureAt(MountedTarget::kWhite, pose, {50, averages});
      for (std::size_t k = 0; k < expected.size(); ++k) {
        const double e = (m.radiance[k] - expected[k]) / expected[k];
        sum += e * e;
      }
    }
    return std::sqrt(sum / (20.0 * static_cast<double>(expected.size())));
  };
  const double single = rms_error(1);
  const double sixteen = rms_error(16);
  EXPECT_GT(single, 0);
  EXPECT_NEAR(sixteen / single, 0.25, 0.05);
}

TEST(RigOpticsTest, IntegratedIsTheSpectrumSummedOverBands) {
  Rig rig;
  const SimMeasurement m = rig.MeasureAt(MountedTarget::kSample, Pose{10, 20, 0, 50});
  double sum = 0;
  for (double r : m.radiance) sum += r * 4.0;
  EXPECT_NEAR(m.integrated, sum, 1e-12 * sum);
}

TEST(RigOpticsTest, SameSeedSameReadingsOtherSeedOtherReadings) {
  auto run = [](std::uint64_t seed) {
    OpticsConfig cfg;
    cfg.seed = seed;
    Rig rig(cfg);
    std::vector<double> all;
    for (const Pose& p : {Pose{0, 0, 0, 0}, Pose{20, 30, 0, 60}, Pose{40, -10, 0, 90}}) {
      const auto m = rig.MeasureAt(MountedTarget::kSample, p);
      all.insert(all.end(), m.radiance.begin(), m.radiance.end());
    }
    return all;
  };
  EXPECT_EQ(run(7), run(7));
  EXPECT_NE(run(7), run(8));
}

TEST(RigOpticsTest, OpticsNeverApplyInjectedCodes) {
  // Injected codes are the PR-650 endpoint's to apply (sim_shared.h); the optics report the light.
  Rig rig;
  SerialFaults f;
  f.quality_code = 29;
  f.quality_count = 2;
  rig.control.set_serial(f);
  EXPECT_EQ(rig.MeasureAt(MountedTarget::kWhite, Pose{}).quality_code, 0);
  EXPECT_EQ(rig.control.serial().quality_count, 2);
  EXPECT_EQ(rig.MeasureAt(MountedTarget::kDark, Pose{}).quality_code, 10);
}

TEST(TrueBrdfTest, MatchesTheAnalyticSampleAndIsZeroBelowTheSurface) {
  const Directions d{30, 0, 40, 180};
  const auto f = TrueBrdf(d);
  const auto grid = WavelengthGrid::Pr650();
  ASSERT_EQ(f.size(), grid.count);
  for (std::size_t k = 0; k < grid.count; ++k) {
    EXPECT_DOUBLE_EQ(f[k], AnalyticBrdf::PaintLike().Evaluate(d, grid.at(k)));
  }
  // Off the specular peak the brushed sample's lobe depends on the azimuth; turning both
  // directions by 90° changes the value.
  EXPECT_NE(TrueBrdf(Directions{30, 0, 30, 160}, true),
            TrueBrdf(Directions{30, 90, 30, 250}, true));
  for (double v : TrueBrdf(Directions{95, 0, 30, 180})) EXPECT_EQ(v, 0);
}

}  // namespace
}  // namespace brdf::sim

namespace brdf::sim {
namespace {

TEST(ManualDetectorPoseTest, TheOpticsSeeTheDetectorWhereTheOperatorPutIt) {
  FixedStage holder;  // a stage without δ reads δ = 0
  holder.pose = Pose{10, 30, 0, 0};
  ManualDetectorPose manual(holder, 60);
  SimControl control;
  OpticsConfig cfg;
  cfg.noise_scale = 0;
  RigOptics through_manual(manual, control, cfg);
  const SimMeasurement m = through_manual.Measure({});
  EXPECT_EQ(m.radiance, through_manual.ExpectedRadiance(MountedTarget::kSample, {10, 30, 0, 60}));
  EXPECT_NE(m.radiance, through_manual.ExpectedRadiance(MountedTarget::kSample, {10, 30, 0, 0}));
  manual.set_delta(20);
  EXPECT_EQ(manual.LivePose(), (Pose{10, 30, 0, 20}));
}

}  // namespace
}  // namespace brdf::sim
