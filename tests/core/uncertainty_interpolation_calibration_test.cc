// core/uncertainty/interpolation_calibration: the fit of the interpolation term's scale to
// held-out residuals, and its application.
#include <gtest/gtest.h>

#include <cmath>
#include <span>
#include <vector>

#include "core/uncertainty/interpolation_calibration.h"

namespace brdf::uncertainty {
namespace {

HeldOutPoint Point(double residual, double spread, double noise, int bands) {
  HeldOutPoint p;
  p.residual.assign(bands, residual);
  p.spread.assign(bands, spread);
  p.noise.assign(bands, noise);
  return p;
}

TEST(FitInterpolationCalibration, TheScaleIsTheConformalRankOfTheNeeds) {
  // 39 points with residual i·0.01 (i = 1..39), s = 0.1, no noise: point i needs
  // c = r / (k·s) = i·0.05; n = 39, rank ⌈0.95 · 40⌉ = 38.
  std::vector<HeldOutPoint> points;
  for (int i = 1; i <= 39; ++i) points.push_back(Point(i * 0.01, 0.1, 0.0, 1));
  const InterpolationCalibration c = FitInterpolationCalibration(points, 1, CalibrationTarget{});
  ASSERT_EQ(c.scale.size(), 1u);
  EXPECT_NEAR(c.scale[0], 38 * 0.05, 1e-12);
  EXPECT_EQ(c.held_out, 39u);
  int inside = 0;
  for (const HeldOutPoint& p : points)
    inside += std::abs(p.residual[0]) <= 2 * c.scale[0] * 0.1 + 1e-15;
  EXPECT_EQ(inside, 38);
}

TEST(FitInterpolationCalibration, ASmallSetTakesItsLargestNeed) {
  // n = 10: rank ⌈0.95 · 11⌉ = 11 > n, so the largest need (point 10: c = 0.5).
  std::vector<HeldOutPoint> points;
  for (int i = 1; i <= 10; ++i) points.push_back(Point(i * 0.01, 0.1, 0.0, 2));
  const InterpolationCalibration c = FitInterpolationCalibration(points, 2, CalibrationTarget{});
  ASSERT_EQ(c.scale.size(), 2u);
  EXPECT_NEAR(c.scale[0], 0.5, 1e-12);
  EXPECT_NEAR(c.scale[1], 0.5, 1e-12);
}

TEST(FitInterpolationCalibration, NoiseThatCoversAResidualNeedsNoScale) {
  std::vector<HeldOutPoint> points;
  for (int i = 0; i < 10; ++i) points.push_back(Point(0.01, 0.1, 0.01, 2));
  const InterpolationCalibration c = FitInterpolationCalibration(points, 2, CalibrationTarget{});
  ASSERT_EQ(c.scale.size(), 2u);
  EXPECT_EQ(c.scale[0], 0.0);
  EXPECT_EQ(c.scale[1], 0.0);
  // Noise that covers part of it: |r|/k = 0.05, noise 0.03, so c · s = 0.04.
  std::vector<HeldOutPoint> partly;
  for (int i = 0; i < 10; ++i) partly.push_back(Point(0.1, 0.2, 0.03, 1));
  EXPECT_NEAR(FitInterpolationCalibration(partly, 1, CalibrationTarget{}).scale[0], 0.2, 1e-12);
}

TEST(FitInterpolationCalibration, BandGroupsAreFittedApart) {
  // Bands 0–1 residual 0.1, bands 2–3 residual −0.4, s = 1: c = |r|/2 in each group.
  std::vector<HeldOutPoint> points;
  for (int i = 0; i < 10; ++i) {
    HeldOutPoint p = Point(0.1, 1.0, 0.0, 4);
    p.residual[2] = p.residual[3] = -0.4;
    points.push_back(p);
  }
  CalibrationTarget target;
  target.band_groups = 2;
  const InterpolationCalibration c = FitInterpolationCalibration(points, 4, target);
  ASSERT_EQ(c.scale.size(), 4u);
  EXPECT_NEAR(c.scale[0], 0.05, 1e-12);
  EXPECT_NEAR(c.scale[1], 0.05, 1e-12);
  EXPECT_NEAR(c.scale[2], 0.2, 1e-12);
  EXPECT_NEAR(c.scale[3], 0.2, 1e-12);
}

TEST(FitInterpolationCalibration, PairsNoScaleCanCoverFallBackToTheLargestFiniteNeed) {
  // 11 points needing c = 0.5, then 9 with s = 0 and a residual beyond the noise (need ∞): the
  // rank ⌈0.95 · 21⌉ = 20 falls on an infinite need.
  std::vector<HeldOutPoint> points;
  for (int i = 0; i < 11; ++i) points.push_back(Point(1.0, 1.0, 0.0, 1));
  for (int i = 0; i < 9; ++i) points.push_back(Point(1.0, 0.0, 0.0, 1));
  const InterpolationCalibration c = FitInterpolationCalibration(points, 1, CalibrationTarget{});
  ASSERT_EQ(c.scale.size(), 1u);
  EXPECT_NEAR(c.scale[0], 0.5, 1e-12);
}

TEST(FitInterpolationCalibration, ASpreadThatIsRoundingCountsAsNone) {
  // As PairsNoScaleCanCoverFallBackToTheLargestFiniteNeed, but the 9 pairs' spread is rounding
  // (1e-16 beside a residual of 1: a held-out reading on another's coordinates). Taken as a
  // spread, the largest finite need would be 5e15; it counts as s = 0 and c stays 0.5.
  std::vector<HeldOutPoint> points;
  for (int i = 0; i < 11; ++i) points.push_back(Point(1.0, 1.0, 0.0, 1));
  for (int i = 0; i < 9; ++i) points.push_back(Point(1.0, 1e-16, 0.0, 1));
  const InterpolationCalibration c = FitInterpolationCalibration(points, 1, CalibrationTarget{});
  ASSERT_EQ(c.scale.size(), 1u);
  EXPECT_NEAR(c.scale[0], 0.5, 1e-12);
  // A need just under the bound is still a need: c = 1e6 · 0.999.
  std::vector<HeldOutPoint> large;
  for (int i = 0; i < 10; ++i) large.push_back(Point(2.0, 1.0 / 0.999e6, 0.0, 1));
  EXPECT_NEAR(FitInterpolationCalibration(large, 1, CalibrationTarget{}).scale[0], 0.999e6, 1e-3);
}

TEST(FitInterpolationCalibration, TooFewOrMisshapenPointsAreNotCalibrated) {
  std::vector<HeldOutPoint> points;
  for (int i = 0; i < 5; ++i) points.push_back(Point(0.1, 1.0, 0.0, 2));
  InterpolationCalibration c = FitInterpolationCalibration(points, 2, CalibrationTarget{});
  EXPECT_TRUE(c.scale.empty());
  EXPECT_NE(c.detail.find("5 held-out readings"), std::string::npos) << c.detail;
  for (int i = 0; i < 10; ++i) points.push_back(Point(0.1, 1.0, 0.0, 3));  // wrong bands
  c = FitInterpolationCalibration(points, 2, CalibrationTarget{});
  EXPECT_TRUE(c.scale.empty());
  EXPECT_EQ(c.held_out, 5u);
}

// Size bins: 30 held-out readings whose |r| / s grows with their cell's size h (h = 1, 2, 3 in
// thirds): each third gets its own c, and a cell larger than every held-out one gets c · h / h_max.
TEST(FitInterpolationCalibration, WithSizeBinsTheScaleGrowsWithTheCellsSize) {
  std::vector<HeldOutPoint> points;
  for (int i = 0; i < 30; ++i) {
    const double h = 1.0 + i / 10;  // 1, 2, 3
    HeldOutPoint p = Point(0.1 * h, 0.1, 0.0, 1);
    p.cell_size = h;
    points.push_back(p);
  }
  CalibrationTarget target;
  target.size_bins = 3;
  const InterpolationCalibration c = FitInterpolationCalibration(points, 1, target);
  ASSERT_EQ(c.scale.size(), 1u);
  ASSERT_EQ(c.larger.size(), 2u) << c.detail;
  EXPECT_DOUBLE_EQ(c.largest_cell, 3.0);
  // Need c = |r| / (k s) = h / 2.
  EXPECT_NEAR(ScaleAt(c, 1.0, 0), 0.5, 1e-12);
  EXPECT_NEAR(ScaleAt(c, 2.0, 0), 1.0, 1e-12);
  EXPECT_NEAR(ScaleAt(c, 3.0, 0), 1.5, 1e-12);
  EXPECT_NEAR(ScaleAt(c, 6.0, 0), 3.0, 1e-12);  // beyond: c · h / h_max
  EXPECT_LT(ScaleAt(c, 0.5, 0), ScaleAt(c, 2.5, 0));
  std::vector<double> spread = {0.1};
  EXPECT_TRUE(ApplyInterpolationCalibration(c, spread, 2.0));
  EXPECT_NEAR(spread[0], 0.1, 1e-12);
  // Without bins the same points get one c, the largest third's rank: too wide for small cells.
  const InterpolationCalibration one = FitInterpolationCalibration(points, 1, CalibrationTarget{});
  EXPECT_TRUE(one.larger.empty());
  EXPECT_NEAR(ScaleAt(one, 1.0, 0), 1.5, 1e-12);
  EXPECT_NEAR(ScaleAt(one, 6.0, 0), 1.5, 1e-12);
}

// A larger bin never gets a smaller c than a smaller one, and beyond the largest held-out cell
// SizeBeyond::kNotEstimated leaves the term unestimated (NaN; Apply refuses).
TEST(FitInterpolationCalibration, SizeBinsNeverShrinkAndMayStopAtTheLargestCell) {
  std::vector<HeldOutPoint> points;
  for (int i = 0; i < 20; ++i) {
    HeldOutPoint p = Point(i < 10 ? 0.4 : 0.1, 0.1, 0.0, 1);  // the small cells err more
    p.cell_size = i < 10 ? 1.0 : 2.0;
    points.push_back(p);
  }
  CalibrationTarget target;
  target.size_bins = 2;
  target.beyond = SizeBeyond::kNotEstimated;
  const InterpolationCalibration c = FitInterpolationCalibration(points, 1, target);
  ASSERT_EQ(c.larger.size(), 1u);
  EXPECT_NEAR(ScaleAt(c, 1.0, 0), 2.0, 1e-12);
  EXPECT_NEAR(ScaleAt(c, 2.0, 0), 2.0, 1e-12);  // not 0.5: never smaller than the smaller cells'
  EXPECT_FALSE(BeyondCalibration(c, 2.0));
  EXPECT_TRUE(BeyondCalibration(c, 2.5));
  EXPECT_TRUE(std::isnan(ScaleAt(c, 2.5, 0)));
  std::vector<double> spread = {0.1};
  EXPECT_FALSE(ApplyInterpolationCalibration(c, spread, 2.5));
  EXPECT_DOUBLE_EQ(spread[0], 0.1);
  // Too few readings for two bins of min_points each: one bin.
  target.min_points = 15;
  EXPECT_TRUE(FitInterpolationCalibration(points, 1, target).larger.empty());
}

TEST(ApplyInterpolationCalibration, ScalesTheSpreadBandByBand) {
  InterpolationCalibration c;
  c.scale = {0.5, 2.0};
  std::vector<double> spread = {1.0, 3.0};
  EXPECT_TRUE(ApplyInterpolationCalibration(c, spread));
  EXPECT_DOUBLE_EQ(spread[0], 0.5);
  EXPECT_DOUBLE_EQ(spread[1], 6.0);
  InterpolationCalibration none;
  std::vector<double> kept = {1.0, 3.0};
  EXPECT_FALSE(ApplyInterpolationCalibration(none, kept));
  EXPECT_DOUBLE_EQ(kept[1], 3.0);
}

TEST(ApplyInterpolationCalibration, WithSizeBinsEachBandGetsScaleAtsValue) {
  InterpolationCalibration c;
  c.scale = {0.5, 2.0, 1.25};
  c.larger = {{1.0, {0.75, 2.5, 1.5}}, {3.0, {1.1, 2.9, 1.7}}};
  // largest_cell 0: bins without a reach (every held-out cell of size 0), still ScaleAt's bins.
  for (double largest : {5.0, 0.0}) {
    c.largest_cell = largest;
    for (SizeBeyond beyond : {SizeBeyond::kGrow, SizeBeyond::kNotEstimated}) {
      c.beyond = beyond;
      for (double h : {0.0, 0.5, 1.0, 2.0, 3.0, 4.9, 5.0, 7.3}) {
        std::vector<double> spread = {1.0 / 3.0, 3.7, 0.011};
        const std::vector<double> before = spread;
        if (!ApplyInterpolationCalibration(c, spread, h)) {
          EXPECT_TRUE(BeyondCalibration(c, h)) << h;
          continue;
        }
        for (std::size_t b = 0; b < spread.size(); ++b) {
          EXPECT_EQ(spread[b], before[b] * ScaleAt(c, h, b))
              << "largest " << largest << " h " << h << " band " << b;
        }
      }
    }
  }
  c.largest_cell = 5;
  // A bin without a scale for every band: the band's own (ScaleAt's rule) still.
  c.beyond = SizeBeyond::kGrow;
  c.larger = {{1.0, {0.75}}};
  std::vector<double> spread = {1.0, 1.0, 1.0};
  ASSERT_TRUE(ApplyInterpolationCalibration(c, spread, 2.0));
  EXPECT_EQ(spread[0], 0.75);
  EXPECT_EQ(spread[1], 2.0);
  EXPECT_EQ(spread[2], 1.25);
}

}  // namespace
}  // namespace brdf::uncertainty
