// daemon/index/interpolation_calibration: a snapshot's calibration (core/uncertainty/held_out.h
// over its samples), computed once for the snapshot.
#include "daemon/index/interpolation_calibration.h"

#include <gtest/gtest.h>

#include <memory>
#include <vector>

#include "daemon/index/cache.h"

namespace brdf::daemon {
namespace {

constexpr int kBands = 4;

// 512 samples of a curved BRDF on an 8 × 8 × 8 grid of (θi, θo, φ), every band alike.
std::shared_ptr<interp::SampleSet> CurvedSamples() {
  auto set = std::make_shared<interp::SampleSet>(3, kBands);
  for (int k = 0; k < 512; ++k) {
    const double c[3] = {10.0 * (k / 64), 10.0 * (k / 8 % 8), 20.0 * (k % 8)};
    const double f = 0.1 + 1e-4 * (c[0] - 40) * (c[0] - 40) + 5e-6 * c[1] * c[2];
    EXPECT_TRUE(set->Add(k + 1, c, std::vector<double>(kBands, f)).ok());
  }
  return set;
}

TEST(CalibrateInterpolation, TheNearestMethodIsNotCalibratedAndSaysWhy) {
  IndexSnapshot snapshot;
  snapshot.method = interp::Method::kNearest;
  snapshot.samples = CurvedSamples();
  snapshot.grid.count = kBands;
  const uncertainty::InterpolationCalibration& c = snapshot.calibration->Get(snapshot);
  EXPECT_TRUE(c.scale.empty());
  EXPECT_NE(c.detail.find("nearest"), std::string::npos) << c.detail;
}

TEST(CalibrateInterpolation, IsComputedOnceForTheSnapshot) {
  IndexSnapshot snapshot;
  snapshot.method = interp::Method::kOctant;
  snapshot.samples = CurvedSamples();
  snapshot.grid.count = kBands;
  EXPECT_FALSE(snapshot.calibration->computed());
  const uncertainty::InterpolationCalibration& c = snapshot.calibration->Get(snapshot);
  ASSERT_EQ(c.scale.size(), static_cast<std::size_t>(kBands));
  EXPECT_GE(c.held_out, 50u);
  EXPECT_TRUE(snapshot.calibration->computed());
  EXPECT_EQ(&snapshot.calibration->Get(snapshot), &c);
}

}  // namespace
}  // namespace brdf::daemon
