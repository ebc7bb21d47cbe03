// core/uncertainty/pose_gradient.h: the sensitivity of a reading to a pose error from its
// neighbours, against the derivative of a known radiance factor worked out here independently.
#include <gtest/gtest.h>

#include <cmath>
#include <numbers>

#include "core/uncertainty/budget.h"
#include "core/uncertainty/pose_gradient.h"

namespace brdf::uncertainty {
namespace {

constexpr double kDeg = std::numbers::pi / 180.0;

// A Lambertian sample (f = 0.3 / π in both bands) on a line along β at α = 0, where θi = |β|.
PosedValue Lambert(double beta, double gamma = 0) {
  return PosedValue{Pose{0, beta, gamma, 30}, std::abs(beta), {0.3 / std::numbers::pi, 0.1}};
}

TEST(PoseGradient, CentralDifferenceOfTheRadianceFactorOverTheReadingsCosine) {
  const std::vector<PosedValue> line = {Lambert(0), Lambert(15), Lambert(30)};
  const std::vector<PoseGradient> g = EstimatePoseGradients(line);
  ASSERT_EQ(g.size(), 3u);
  // β = 15°: (f cos 30° − f cos 0°) / 30° / cos 15°, per degree.
  const double f = 0.3 / std::numbers::pi;
  ASSERT_EQ(g[1][1].size(), 2u);
  EXPECT_NEAR(g[1][1][0], f * (std::cos(30 * kDeg) - 1.0) / 30.0 / std::cos(15 * kDeg), 1e-15);
  // The reported f of a Lambertian reading moves as −f · tan θi per radian: the difference over
  // ±15° is within 2 % of it.
  EXPECT_NEAR(g[1][1][0] / (-f * std::tan(15 * kDeg) * kDeg), 1.0, 0.02);
  // At the edges one-sided: β = 0 from 0 → 15°, β = 30° from 15° → 30°.
  EXPECT_NEAR(g[0][1][0], f * (std::cos(15 * kDeg) - 1.0) / 15.0, 1e-15);
  EXPECT_NEAR(g[2][1][0],
              f * (std::cos(30 * kDeg) - std::cos(15 * kDeg)) / 15.0 / std::cos(30 * kDeg), 1e-15);
  // No reading differs in α, γ or δ alone: those axes have no estimate.
  for (const PoseGradient& r : g) {
    EXPECT_TRUE(r[0].empty());
    EXPECT_TRUE(r[2].empty());
    EXPECT_TRUE(r[3].empty());
  }
}

TEST(PoseGradient, OnlyReadingsWithTheOtherAxesEqualAreNeighbours) {
  // β = 15° at γ = 0 and β = 30° at γ = 5°: not on one line along β; on none along γ either.
  std::vector<PosedValue> readings = {Lambert(15), Lambert(30, 5)};
  std::vector<PoseGradient> g = EstimatePoseGradients(readings);
  EXPECT_TRUE(g[0][1].empty());
  EXPECT_TRUE(g[1][1].empty());
  // γ = 0 and 5° at β = 30°: a line along γ; the isotropic sample does not change along it.
  readings = {Lambert(30, 0), Lambert(30, 5)};
  g = EstimatePoseGradients(readings);
  ASSERT_EQ(g[0][2].size(), 2u);
  EXPECT_DOUBLE_EQ(g[0][2][0], 0.0);
}

TEST(PoseGradient, ARepeatIsNoNeighbourOfItsTwin) {
  PosedValue twin = Lambert(15);
  twin.value = {0.2, 0.2};  // a noisy repeat would give a slope over 0°: it must give none
  std::vector<PosedValue> readings = {Lambert(15), twin};
  std::vector<PoseGradient> g = EstimatePoseGradients(readings);
  EXPECT_TRUE(g[0][1].empty());
  EXPECT_TRUE(g[1][1].empty());
  readings.push_back(Lambert(30));
  g = EstimatePoseGradients(readings);
  const double f = 0.3 / std::numbers::pi;
  ASSERT_EQ(g[2][1].size(), 2u);
  // β = 30° takes its slope from the twins' mean at 15° (0.2 and f in band 0); the twins from
  // their own mean and β = 30°.
  const double twins = (f + 0.2) / 2 * std::cos(15 * kDeg);
  EXPECT_NEAR(g[2][1][0], (f * std::cos(30 * kDeg) - twins) / 15.0 / std::cos(30 * kDeg), 1e-15);
  ASSERT_EQ(g[0][1].size(), 2u);
  EXPECT_NEAR(g[0][1][0], (f * std::cos(30 * kDeg) - twins) / 15.0 / std::cos(15 * kDeg), 1e-15);
  EXPECT_DOUBLE_EQ(g[0][1][0], g[1][1][0]);
}

TEST(PoseGradient, UnusableReadingsGetNone) {
  PosedValue grazing = Lambert(30);
  grazing.theta_i_deg = 90;
  PosedValue short_one = Lambert(45);
  short_one.value.pop_back();
  const std::vector<PosedValue> readings = {Lambert(15), grazing, short_one};
  const std::vector<PoseGradient> g = EstimatePoseGradients(readings);
  for (const PoseGradient& r : g) {
    for (const std::vector<double>& axis : r) EXPECT_TRUE(axis.empty());
  }
}

TEST(PoseGradient, TheBudgetNamesAnUncertainAxisWithoutAGradient) {
  BudgetInputs in;
  in.session_id = 7;
  in.grid = WavelengthGrid{500, 4, 2};
  in.sample = MeasuredSignal{13, {0.05, 0.06}, 1000, 4};
  in.reference = MeasuredSignal{11, {0.2, 0.2}, 1000, 4};
  in.white_reflectance = {0.99};
  in.white_reflectance_u = {0.005};
  in.theta_i_deg = 30;
  in.terms.stage.repeatability_deg = {0.1, 0.1, 0.1, 0.0};
  in.pose_gradient = PoseGradient{std::vector<double>{0.01, 0.02}, std::vector<double>{},
                                  std::vector<double>{}, std::vector<double>{}};
  Result<ReadingBudget> budget = EstimateReadingBudget(in);
  ASSERT_TRUE(budget.ok()) << budget.status().message();
  // α alone counts; β and γ are named; δ, with no uncertainty, is not.
  ASSERT_NE(budget->Find("pose_repeatability"), nullptr);
  EXPECT_NEAR(budget->Find("pose_repeatability")->contribution[1], 0.002, 1e-15);
  int named_beta = 0, named_gamma = 0, named_delta = 0;
  for (const std::string& why : budget->not_estimated) {
    named_beta += why.rfind("pose_beta:", 0) == 0;
    named_gamma += why.rfind("pose_gamma:", 0) == 0;
    named_delta += why.rfind("pose_delta:", 0) == 0;
  }
  EXPECT_EQ(named_beta, 1);
  EXPECT_EQ(named_gamma, 1);
  EXPECT_EQ(named_delta, 0);
  // A gradient of the wrong size is refused by name.
  in.pose_gradient->at(3) = {1.0};
  EXPECT_NE(EstimateReadingBudget(in).status().message().find("delta"), std::string::npos);
}

}  // namespace
}  // namespace brdf::uncertainty
