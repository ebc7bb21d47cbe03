// The rig's known errors (tools/brdf-sim/optics/errors.h) as the simulated meter shows them: off by
// default (no reading moves), each one's effect on sample, white and dark readings against its
// stated model, each reproducible from the seed, and each drawn from its own stream.
#include <gtest/gtest.h>

#include <cmath>
#include <numbers>
#include <vector>

#include "core/geometry.h"
#include "tools/brdf-sim/optics/errors.h"
#include "tools/brdf-sim/optics/optics.h"

namespace brdf::sim {
namespace {

constexpr double kPi = std::numbers::pi;

class FixedStage final : public StagePoseSource {
 public:
  Pose LivePose() const override { return pose; }
  Pose pose;
};

// Noiseless optics (the detector's noise off) with `errors` on, at a fixed pose.
struct Rig {
  explicit Rig(ErrorSources errors, std::uint64_t seed = 5, double noise_scale = 0)
      : optics(stage, control, Config(errors, seed, noise_scale)) {}
  static OpticsConfig Config(ErrorSources errors, std::uint64_t seed, double noise_scale) {
    OpticsConfig c;
    c.errors = errors;
    c.seed = seed;
    c.noise_scale = noise_scale;
    return c;
  }
  SimMeasurement MeasureAt(MountedTarget target, const Pose& pose, MeterSetup setup = {100, 1}) {
    control.set_mounted(target);
    stage.pose = pose;
    return optics.Measure(setup);
  }
  FixedStage stage;
  SimControl control;
  RigOptics optics;
};

double Mean(const std::vector<double>& v) {
  double s = 0;
  for (double x : v) s += x;
  return s / static_cast<double>(v.size());
}

double StdDev(const std::vector<double>& v) {
  const double m = Mean(v);
  double s = 0;
  for (double x : v) s += (x - m) * (x - m);
  return std::sqrt(s / static_cast<double>(v.size() - 1));
}

TEST(RigErrorsTest, OffByDefault) {
  const RigErrors e(ErrorSources{}, 3);
  EXPECT_EQ(e.white_factor(), 1.0);
  EXPECT_EQ(e.wavelength_shift_nm(), 0.0);
  EXPECT_EQ(e.LampFactor(), 1.0);
  RigErrors m(ErrorSources{}, 3);
  m.AdvanceLamp(36000);
  EXPECT_EQ(m.LampFactor(), 1.0);
  EXPECT_EQ(m.TruePose({1, 2, 3, 4}), (Pose{1, 2, 3, 4}));
  EXPECT_EQ(m.NextGain(), 1.0);
}

TEST(RigErrorsTest, EachSourceDrawsFromItsOwnStream) {
  ErrorSources s;
  s.pose_jitter_deg = 0.2;
  s.gain_noise = 0.01;
  RigErrors a(s, 9), b(s, 9);
  for (int i = 0; i < 10; ++i) {
    const Pose pa = a.TruePose({10, 20, 0, 40});
    b.NextGain();  // b draws gains in between: its poses must not change
    b.AdvanceLamp(5);
    EXPECT_EQ(pa, b.TruePose({10, 20, 0, 40}));
  }
  // The once-per-run draws do not depend on which sources are on.
  ErrorSources white_only;
  white_only.white_error = 0.01;
  ErrorSources both = white_only;
  both.wavelength_shift_sigma_nm = 1;
  EXPECT_EQ(RigErrors(white_only, 4).white_factor(), RigErrors(both, 4).white_factor());
  EXPECT_NE(RigErrors(white_only, 4).white_factor(), RigErrors(white_only, 5).white_factor());
}

TEST(RigErrorsTest, GainScalesAWholeMeasurementBySigmaAcrossMeasurements) {
  ErrorSources s;
  s.gain_noise = 0.02;
  Rig rig(s);
  const Pose pose{0, 20, 0, 40};
  const std::vector<double> expected = rig.optics.ExpectedRadiance(MountedTarget::kSample, pose);
  std::vector<double> gains;
  for (int i = 0; i < 400; ++i) {
    const SimMeasurement m = rig.MeasureAt(MountedTarget::kSample, pose);
    const double g = m.radiance[50] / expected[50];
    for (std::size_t k = 0; k < expected.size(); k += 10) {
      ASSERT_NEAR(m.radiance[k] / expected[k], g, 1e-12) << "one gain for every band";
    }
    gains.push_back(g);
  }
  EXPECT_NEAR(Mean(gains), 1.0, 4 * 0.02 / 20);
  EXPECT_NEAR(StdDev(gains), 0.02, 0.02 * 0.15);
}

TEST(RigErrorsTest, LampDriftsWithTheMetersClock) {
  ErrorSources s;
  s.lamp_drift_per_hour = 0.036;  // 1e-5 per simulated second
  Rig rig(s);
  const Pose pose{0, 0, 0, 0};
  const SimMeasurement first = rig.MeasureAt(MountedTarget::kWhite, pose);  // 0.1 s + 1 s overhead
  ASSERT_DOUBLE_EQ(first.duration_s, 1.1);
  for (int i = 0; i < 49; ++i) rig.MeasureAt(MountedTarget::kWhite, pose);
  const SimMeasurement last = rig.MeasureAt(MountedTarget::kWhite, pose);
  // 50 measurements of 1.1 s before the last: its lamp is 1 + 1e-5 · 55 brighter.
  for (std::size_t k = 0; k < last.radiance.size(); k += 20) {
    const double ambient = rig.optics.config().ambient_radiance;
    EXPECT_NEAR((last.radiance[k] - ambient) / (first.radiance[k] - ambient), 1.00055, 1e-9);
  }
  // A dark reading has no lamp in it.
  const SimMeasurement dark = rig.MeasureAt(MountedTarget::kDark, pose);
  EXPECT_EQ(dark.radiance[0], rig.optics.config().ambient_radiance);
}

TEST(RigErrorsTest, LampWanderIsARandomWalkInSqrtTime) {
  ErrorSources s;
  s.lamp_wander_per_sqrt_hour = 0.006;  // 1e-4 per sqrt(second)
  std::vector<double> steps;
  for (std::uint64_t seed = 1; seed <= 40; ++seed) {
    RigErrors e(s, seed);
    double before = e.LampFactor();
    for (int i = 0; i < 25; ++i) {
      e.AdvanceLamp(4.0);  // σ per step: 1e-4 · 2
      steps.push_back(e.LampFactor() - before);
      before = e.LampFactor();
    }
  }
  EXPECT_NEAR(StdDev(steps), 2e-4, 2e-4 * 0.1);
  EXPECT_NEAR(Mean(steps), 0.0, 4 * 2e-4 / std::sqrt(1000.0));
}

TEST(RigErrorsTest, WhiteErrorIsOneFactorForTheRunOnWhiteReadingsOnly) {
  ErrorSources s;
  s.white_error = 0.01;
  std::vector<double> factors;
  for (std::uint64_t seed = 1; seed <= 300; ++seed) {
    Rig rig(s, seed);
    const Pose pose{0, 10, 0, 30};
    Rig clean(ErrorSources{}, seed);
    const auto w = rig.MeasureAt(MountedTarget::kWhite, pose);
    const auto w_clean = clean.MeasureAt(MountedTarget::kWhite, pose);
    const double ambient = rig.optics.config().ambient_radiance;
    const double f = (w.radiance[60] - ambient) / (w_clean.radiance[60] - ambient);
    EXPECT_NEAR(f, rig.optics.errors().white_factor(), 1e-12);
    if (seed <= 3) {
      // The same factor in every band and in the next white reading; samples untouched.
      const auto again = rig.MeasureAt(MountedTarget::kWhite, pose);
      EXPECT_NEAR((again.radiance[10] - ambient) / (w_clean.radiance[10] - ambient), f, 1e-12);
      EXPECT_EQ(rig.MeasureAt(MountedTarget::kSample, pose).radiance,
                clean.MeasureAt(MountedTarget::kSample, pose).radiance);
    }
    factors.push_back(f);
  }
  EXPECT_NEAR(Mean(factors), 1.0, 4 * 0.01 / std::sqrt(300.0));
  EXPECT_NEAR(StdDev(factors), 0.01, 0.01 * 0.15);
}

TEST(RigErrorsTest, PoseJitterMovesTheLightAsTheGeometrySays) {
  ErrorSources s;
  s.pose_jitter_deg = 0.3;
  Rig rig(s);
  // The white at β = 60°, α = 0: I0 ∝ cos α cos β; a β error dβ changes it by −tan β · dβ, an α
  // error only to second order.
  const Pose pose{0, 60, 0, 60};
  const double nominal = rig.optics.ExpectedRadiance(MountedTarget::kWhite, pose)[50];
  const double ambient = rig.optics.config().ambient_radiance;
  std::vector<double> rel;
  for (int i = 0; i < 400; ++i) {
    const double r = rig.MeasureAt(MountedTarget::kWhite, pose).radiance[50];
    rel.push_back((r - ambient) / (nominal - ambient) - 1);
  }
  const double expected = std::tan(60 * kPi / 180) * 0.3 * kPi / 180;
  EXPECT_NEAR(StdDev(rel), expected, expected * 0.15);
}

TEST(RigErrorsTest, WavelengthShiftMovesEveryBand) {
  ErrorSources s;
  s.wavelength_shift_nm = 2;
  Rig rig(s);
  const Lamp& lamp = rig.optics.lamp();
  const material::Material paint = SampleMaterial(false);
  const Pose pose{10, 20, 0, 50};
  const Directions d = PoseToDirections(pose);
  const double cos_i = std::cos(d.theta_i * kPi / 180);
  const auto white = rig.MeasureAt(MountedTarget::kWhite, pose);
  const auto sample = rig.MeasureAt(MountedTarget::kSample, pose);
  const double ambient = rig.optics.config().ambient_radiance;
  const WavelengthGrid grid = WavelengthGrid::Pr650();
  for (std::size_t k = 0; k < grid.count; k += 5) {
    const double nm = grid.at(k) + 2;
    EXPECT_NEAR(white.radiance[k] - ambient, lamp.Irradiance(nm) * 0.99 / kPi * cos_i,
                1e-12 * white.radiance[k]);
    EXPECT_NEAR(sample.radiance[k] - ambient, lamp.Irradiance(nm) * paint.Evaluate(d, nm) * cos_i,
                1e-12 * sample.radiance[k]);
  }
  // A drawn shift: the same for the run, different between seeds, spread as configured.
  ErrorSources drawn;
  drawn.wavelength_shift_sigma_nm = 1.5;
  std::vector<double> shifts;
  for (std::uint64_t seed = 1; seed <= 300; ++seed) {
    shifts.push_back(RigErrors(drawn, seed).wavelength_shift_nm());
  }
  EXPECT_NEAR(StdDev(shifts), 1.5, 1.5 * 0.15);
}

TEST(RigErrorsTest, StrayLightAddsToLitReadingsNotToTheDark) {
  ErrorSources s;
  s.stray_light = 0.002;
  Rig rig(s);
  Rig clean(ErrorSources{});
  const Lamp& lamp = rig.optics.lamp();
  const WavelengthGrid grid = WavelengthGrid::Pr650();
  const Pose pose{10, 20, 0, 50};
  const Pose away{0, 120, 0, 120};  // the lamp behind the surface
  for (MountedTarget t : {MountedTarget::kSample, MountedTarget::kWhite}) {
    const auto with = rig.optics.ExpectedRadiance(t, pose);
    const auto without = clean.optics.ExpectedRadiance(t, pose);
    const auto behind = rig.optics.ExpectedRadiance(t, away);
    for (std::size_t k = 0; k < grid.count; k += 10) {
      const double stray = 0.002 * lamp.Irradiance(grid.at(k)) / kPi;
      EXPECT_NEAR(with[k] - without[k], stray, 1e-12 * with[k]);
      EXPECT_NEAR(behind[k] - rig.optics.config().ambient_radiance, stray, 1e-12 * stray);
    }
  }
  EXPECT_EQ(rig.optics.ExpectedRadiance(MountedTarget::kDark, pose),
            clean.optics.ExpectedRadiance(MountedTarget::kDark, pose));
}

TEST(RigErrorsTest, EverythingOnIsReproducibleFromTheSeed) {
  ErrorSources s;
  s.gain_noise = 0.01;
  s.lamp_drift_per_hour = 0.01;
  s.lamp_wander_per_sqrt_hour = 0.01;
  s.white_error = 0.01;
  s.pose_jitter_deg = 0.1;
  s.wavelength_shift_sigma_nm = 1;
  s.stray_light = 0.001;
  auto run = [&](std::uint64_t seed) {
    Rig rig(s, seed, /*noise_scale=*/1);
    std::vector<double> all;
    for (const Pose& p : {Pose{0, 0, 0, 0}, Pose{20, 30, 0, 60}, Pose{40, -10, 0, 90}}) {
      for (MountedTarget t : {MountedTarget::kWhite, MountedTarget::kSample}) {
        const auto m = rig.MeasureAt(t, p, {});
        all.insert(all.end(), m.radiance.begin(), m.radiance.end());
      }
    }
    return all;
  };
  EXPECT_EQ(run(7), run(7));
  EXPECT_NE(run(7), run(8));
}

TEST(RigErrorsTest, DefaultsLeaveTheDetectorNoiseStreamAsItWas) {
  // The same seed with and without the (off) error sources set explicitly: identical readings,
  // and the detector's draws unchanged by error sources that draw from their own streams.
  ErrorSources white_only_sources;
  white_only_sources.white_error =
      0.02;  // drawn once, from the session stream: the noise is untouched
  Rig plain(ErrorSources{}, 13, 1), with_white(white_only_sources, 13, 1);
  const Pose pose{20, 30, 0, 60};
  EXPECT_EQ(plain.MeasureAt(MountedTarget::kSample, pose, {}).radiance,
            with_white.MeasureAt(MountedTarget::kSample, pose, {}).radiance);
}

}  // namespace
}  // namespace brdf::sim
