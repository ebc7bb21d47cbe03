// core/uncertainty/interpolated: one interpolated answer's uncertainty as the API and the grid
// export give it — the vertices' budgets blended (a shared term linearly, an independent one in
// quadrature), the interpolation term from the vertices' spread, and what is not estimated.
#include <gtest/gtest.h>

#include <cmath>
#include <memory>
#include <vector>

#include "core/uncertainty/interpolated.h"

namespace brdf::uncertainty {
namespace {

// A one-band budget in the blend's form: a white-standard term shared through session 5 (a
// float, so the sums by hand below hold to its rounding, 2⁻²⁴ relative: 1e-10 here) and an
// independent one.
BlendBudget TwoTermBudget(double white, double signal, NameCodes& codes) {
  ReadingBudget b;
  b.components = {Component{"white_standard", {Sharing::kWhiteStandard, 5}, {white}},
                  Component{"sample_signal", {Sharing::kIndependent, 0}, {signal}}};
  b.combined = {std::hypot(white, signal)};
  b.independent = {std::abs(signal)};
  return *ToBlendBudget(b, codes);
}

struct TwoVertices {
  interp::SampleSet samples{3, 1};
  NameCodes codes;
  std::vector<BlendBudget> budgets;
  interp::Interpolation answer;

  TwoVertices() {
    const double at_a[3] = {10, 20, 30};
    const double at_b[3] = {12, 20, 30};
    const double f_a[1] = {0.30};
    const double f_b[1] = {0.50};
    EXPECT_TRUE(samples.Add(101, at_a, f_a).ok());
    EXPECT_TRUE(samples.Add(102, at_b, f_b).ok());
    budgets = {TwoTermBudget(0.003, 0.004, codes), TwoTermBudget(0.005, 0.012, codes)};
    answer.method = interp::Method::kOctant;
    answer.spectrum = {0.25 * 0.30 + 0.75 * 0.50};
    answer.vertices = {interp::Vertex{101, 0, {}, 0.25}, interp::Vertex{102, 1, {}, 0.75}};
  }
  InterpolatedInputs Inputs() const {
    InterpolatedInputs in;
    in.samples = &samples;
    in.budget_of = [this](std::size_t i) { return &budgets.at(i); };
    return in;
  }
};

TEST(InterpolatedUncertainty, BlendOfASharedAndAnIndependentTermByHand) {
  const TwoVertices v;
  const InterpolatedUncertainty u = EstimateInterpolatedUncertainty(v.answer, v.Inputs());
  // Shared: (0.25·0.003 + 0.75·0.005)² = 0.0045²; independent: (0.25·0.004)² + (0.75·0.012)²
  // = 0.001² + 0.009²; measurement = sqrt(0.0045² + 0.001² + 0.009²) = 0.010111874...
  ASSERT_EQ(u.measurement.size(), 1u);
  EXPECT_NEAR(u.shared[0], 0.0045, 1e-10);
  EXPECT_NEAR(u.measurement[0], std::sqrt(0.0045 * 0.0045 + 0.001 * 0.001 + 0.009 * 0.009), 1e-10);
  EXPECT_NEAR(u.measurement[0], 0.0101118742, 1e-9);
  // Interpolation: y = 0.45; sqrt(0.25·(0.30 − 0.45)² + 0.75·(0.50 − 0.45)²) = sqrt(0.0075).
  ASSERT_EQ(u.interpolation.size(), 1u);
  EXPECT_NEAR(u.interpolation[0], std::sqrt(0.0075), 1e-15);
  EXPECT_TRUE(u.not_estimated.empty());
}

TEST(InterpolatedUncertainty, AReadingWithoutBudgetIsNamedNotCountedAsZero) {
  TwoVertices v;
  InterpolatedInputs in = v.Inputs();
  in.budget_of = [&v](std::size_t i) { return i == 0 ? &v.budgets[0] : nullptr; };
  const InterpolatedUncertainty u = EstimateInterpolatedUncertainty(v.answer, in);
  ASSERT_EQ(u.measurement.size(), 1u);
  EXPECT_NEAR(u.measurement[0], 0.25 * std::hypot(0.003, 0.004), 1e-10);
  ASSERT_EQ(u.not_estimated.size(), 1u);
  EXPECT_NE(u.not_estimated[0].find("reading 102: no uncertainty budget"), std::string::npos);
}

TEST(InterpolatedUncertainty, NoBudgetsForTheQuantitySaysWhy) {
  TwoVertices v;
  InterpolatedInputs in = v.Inputs();
  in.budget_of = nullptr;
  in.no_budgets = "the budgets are of the BRDF";
  const InterpolatedUncertainty u = EstimateInterpolatedUncertainty(v.answer, in);
  EXPECT_TRUE(u.measurement.empty());
  EXPECT_TRUE(u.shared.empty());
  EXPECT_EQ(u.interpolation.size(), 1u);
  ASSERT_EQ(u.not_estimated.size(), 1u);
  EXPECT_EQ(u.not_estimated[0], "measurement: the budgets are of the BRDF");
}

TEST(InterpolatedUncertainty, NearestHasNoInterpolationTermAndAFailedAnswerNothing) {
  TwoVertices v;
  v.answer.method = interp::Method::kNearest;
  v.answer.spectrum = {0.30};
  v.answer.vertices = {interp::Vertex{101, 0, {}, 1.0}};
  const InterpolatedUncertainty u = EstimateInterpolatedUncertainty(v.answer, v.Inputs());
  EXPECT_NEAR(u.measurement[0], std::hypot(0.003, 0.004), 1e-10);
  EXPECT_TRUE(u.interpolation.empty());
  ASSERT_EQ(u.not_estimated.size(), 1u);
  EXPECT_EQ(u.not_estimated[0].rfind("interpolation: the nearest method", 0), 0u);

  v.answer.status = interp::InterpStatus::kEmptyOctant;
  const InterpolatedUncertainty none = EstimateInterpolatedUncertainty(v.answer, v.Inputs());
  EXPECT_TRUE(none.measurement.empty() && none.interpolation.empty() && none.not_estimated.empty());
}

}  // namespace
}  // namespace brdf::uncertainty
