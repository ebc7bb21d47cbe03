// core/uncertainty/held_out: readings held out of an index in hashed folds and predicted from
// the others, the calibration from them, and a calibration computed once.
#include <gtest/gtest.h>

#include <atomic>
#include <cmath>
#include <functional>
#include <memory>
#include <thread>
#include <vector>

#include "core/uncertainty/held_out.h"

namespace brdf::uncertainty {
namespace {

constexpr int kBands = 4;

// Samples on a (θi, θo, φ) grid, every 10° in θ up to 80° and 20° in φ up to 180° (810), band b
// of each the function's value plus 0.01·b.
std::shared_ptr<interp::SampleSet> Grid(const std::function<double(double, double, double)>& f) {
  auto set = std::make_shared<interp::SampleSet>(3, kBands);
  std::int64_t id = 1;
  for (double ti = 0; ti <= 80; ti += 10) {
    for (double to = 0; to <= 80; to += 10) {
      for (double phi = 0; phi <= 180; phi += 20) {
        std::vector<double> spectrum(kBands);
        for (int b = 0; b < kBands; ++b) spectrum[b] = f(ti, to, phi) + 0.01 * b;
        const double c[3] = {ti, to, phi};
        EXPECT_TRUE(set->Add(id++, c, spectrum).ok());
      }
    }
  }
  return set;
}

double Linear(double ti, double to, double phi) {
  return 0.1 + 0.001 * ti + 0.002 * to + 0.0005 * phi;
}
double Curved(double ti, double to, double phi) {
  return 0.1 + 1e-4 * (ti - 40) * (ti - 40) + 5e-5 * (to - phi / 3) * (to - phi / 3);
}

TEST(PredictHeldOut, ALinearBrdfIsPredictedExactlyAndTheScaleIsZero) {
  const auto set = Grid(Linear);
  const auto points =
      PredictHeldOut(*set, IndependentOf{}, interp::Method::kDelaunay, interp::Options{});
  ASSERT_GE(points.size(), 100u);  // the interior readings, at least
  EXPECT_LE(points.size(), kMaxHeldOut);
  for (const HeldOutPoint& p : points) {
    ASSERT_EQ(p.residual.size(), static_cast<std::size_t>(kBands));
    for (double r : p.residual) EXPECT_NEAR(r, 0.0, 1e-12);
    EXPECT_TRUE(p.noise.empty());  // no budgets
  }
  const auto fit = FitInterpolationCalibration(points, kBands, {});
  ASSERT_EQ(fit.scale.size(), static_cast<std::size_t>(kBands));
  EXPECT_LT(fit.scale[0], 1e-6);
}

TEST(PredictHeldOut, AHeldOutReadingIsNotItsOwnVertexAndTheFoldsAreFixed) {
  // On a curved BRDF a reading predicted with itself in the index would have residual 0.
  const auto set = Grid(Curved);
  const auto first = PredictHeldOut(*set, IndependentOf{}, interp::Method::kOctant, {});
  const auto again = PredictHeldOut(*set, IndependentOf{}, interp::Method::kOctant, {});
  ASSERT_GE(first.size(), 50u);
  ASSERT_EQ(first.size(), again.size());
  std::size_t nonzero = 0;
  for (std::size_t i = 0; i < first.size(); ++i) {
    EXPECT_EQ(first[i].residual, again[i].residual);
    EXPECT_EQ(first[i].spread, again[i].spread);
    nonzero += std::abs(first[i].residual[0]) > 1e-9;
  }
  EXPECT_GT(nonzero, first.size() * 9 / 10);
  const auto fit = FitInterpolationCalibration(first, kBands, {});
  ASSERT_EQ(fit.scale.size(), static_cast<std::size_t>(kBands));
  EXPECT_GT(fit.scale[0], 0.0);
}

TEST(CalibrateInterpolation, TheNearestMethodIsNotCalibratedAndSaysWhy) {
  const InterpolationCalibration c =
      CalibrateInterpolation(*Grid(Linear), IndependentOf{}, interp::Method::kNearest, {}, kBands);
  EXPECT_TRUE(c.scale.empty());
  EXPECT_NE(c.detail.find("nearest"), std::string::npos) << c.detail;
}

TEST(CalibrateInterpolation, ABudgetsIndependentPartIsTheHeldOutPointsNoise) {
  const auto set = Grid(Curved);
  ReadingBudget budget;
  budget.independent.assign(kBands, 0.003);
  const auto points = PredictHeldOut(*set, [&budget](std::size_t) { return &budget.independent; },
                                     interp::Method::kOctant, {});
  ASSERT_FALSE(points.empty());
  for (const HeldOutPoint& p : points) {
    ASSERT_EQ(p.noise.size(), static_cast<std::size_t>(kBands));
    // Its own 0.003 and its vertices' (weights summing to 1, each weight² ≤ weight): between
    // 0.003 and 0.003 · √2.
    EXPECT_GE(p.noise[0], 0.003 - 1e-15);
    EXPECT_LE(p.noise[0], 0.003 * std::sqrt(2.0) + 1e-15);
  }
}

// Delaunay's calibration has cell-size bins (its large cells across gaps err more, relative to
// their spread, than its small ones); each held-out point carries its cell's size, and a cell
// larger than every held-out one gets a larger c. The octant method's has one c.
TEST(CalibrateInterpolation, DelaunaysScaleGrowsWithTheCellsSize) {
  EXPECT_EQ(TargetOf(interp::Method::kDelaunay).size_bins, kDelaunaySizeBins);
  EXPECT_EQ(TargetOf(interp::Method::kOctant).size_bins, 1);
  const auto set = Grid(Curved);
  const auto points =
      PredictHeldOut(*set, IndependentOf{}, interp::Method::kDelaunay, interp::Options{});
  for (const HeldOutPoint& p : points) EXPECT_GT(p.cell_size, 0.0);
  const InterpolationCalibration c =
      CalibrateInterpolation(*set, IndependentOf{}, interp::Method::kDelaunay, {}, kBands);
  ASSERT_FALSE(c.scale.empty()) << c.detail;
  ASSERT_EQ(c.larger.size(), static_cast<std::size_t>(kDelaunaySizeBins - 1)) << c.detail;
  EXPECT_GT(c.largest_cell, 0.0);
  for (std::size_t b = 0; b < c.scale.size(); ++b) {
    double previous = ScaleAt(c, 0.0, b);
    for (const SizeBin& bin : c.larger) {
      EXPECT_GE(ScaleAt(c, bin.above + 1e-9, b), previous);
      previous = ScaleAt(c, bin.above + 1e-9, b);
    }
    EXPECT_GT(ScaleAt(c, 2 * c.largest_cell, b), ScaleAt(c, c.largest_cell, b));
  }
  EXPECT_TRUE(CalibrateInterpolation(*set, IndependentOf{}, interp::Method::kOctant, {}, kBands)
                  .larger.empty());
}

TEST(CalibrationOnce, ComputesOnceForAllItsUsers) {
  CalibrationOnce once;
  EXPECT_FALSE(once.computed());
  std::atomic<int> calls{0};
  auto compute = [&calls] {
    ++calls;
    InterpolationCalibration c;
    c.scale = {0.5};
    return c;
  };
  std::vector<std::thread> users;
  for (int t = 0; t < 4; ++t)
    users.emplace_back([&] { EXPECT_EQ(once.Get(compute).scale[0], 0.5); });
  for (std::thread& t : users) t.join();
  EXPECT_EQ(calls.load(), 1);
  EXPECT_TRUE(once.computed());
}

}  // namespace
}  // namespace brdf::uncertainty
