// core/uncertainty/blend: an interpolated value's measurement uncertainty from its vertices'
// budgets (in the blend's form, blend_budget.h: shared contributions as floats), shared terms
// correlated, and the interpolation term from the vertices' spread.
#include <gtest/gtest.h>

#include <array>
#include <cmath>
#include <span>
#include <string>
#include <vector>

#include "core/uncertainty/blend.h"

namespace brdf::uncertainty {
namespace {

// A shared contribution as the blend reads it: rounded to float, widened back.
double F(double u) {
  return static_cast<float>(u);
}

Component Make(const std::string& name, Sharing kind, std::int64_t id, std::vector<double> c) {
  return Component{name, SharedThrough{kind, id}, std::move(c)};
}

// A budget of the given components, combined and independent filled in as the budget does.
ReadingBudget WholeBudget(std::vector<Component> components) {
  ReadingBudget b;
  const std::size_t bands = components.front().contribution.size();
  b.combined.assign(bands, 0.0);
  b.independent.assign(bands, 0.0);
  for (const Component& c : components) {
    for (std::size_t k = 0; k < bands; ++k) {
      b.combined[k] += c.contribution[k] * c.contribution[k];
      if (c.shared.kind == Sharing::kIndependent) {
        b.independent[k] += c.contribution[k] * c.contribution[k];
      }
    }
  }
  for (double& v : b.combined) v = std::sqrt(v);
  for (double& v : b.independent) v = std::sqrt(v);
  b.components = std::move(components);
  return b;
}

// The same in the blend's form, its names coded by one table for the whole test (the tests blend
// budgets made here with each other).
BlendBudget Blendable(const ReadingBudget& whole) {
  static NameCodes codes;
  Result<BlendBudget> b = ToBlendBudget(whole, codes);
  EXPECT_TRUE(b.ok()) << b.status().message();
  return b.ok() ? *std::move(b) : BlendBudget{};
}

BlendBudget Budget(std::vector<Component> components) {
  return Blendable(WholeBudget(std::move(components)));
}

TEST(BlendUncertainty, SharedWhiteStandardAddsLinearly) {
  // Two vertices whose only term is the session's white standard: one error seen by both, so the
  // blend carries Σ wᵢ uᵢ, not the quadrature sum.
  const BlendBudget a = Budget({Make("white_standard", Sharing::kWhiteStandard, 7, {0.02, 0.04})});
  const BlendBudget b = Budget({Make("white_standard", Sharing::kWhiteStandard, 7, {0.04, 0.02})});
  const std::vector<BlendVertex> v = {{1, 0.25, &a}, {2, 0.75, &b}};
  Result<BlendedUncertainty> u = BlendMeasurementUncertainty(v, 2);
  ASSERT_TRUE(u.ok()) << u.status().message();
  EXPECT_NEAR(u->measurement[0], 0.25 * F(0.02) + 0.75 * F(0.04), 1e-15);
  EXPECT_NEAR(u->measurement[1], 0.25 * F(0.04) + 0.75 * F(0.02), 1e-15);
  EXPECT_NEAR(u->shared[0], u->measurement[0], 1e-15);
  EXPECT_TRUE(u->not_estimated.empty());
}

TEST(BlendUncertainty, IndependentTermsAddInQuadrature) {
  const BlendBudget a = Budget({Make("sample_signal", Sharing::kIndependent, 0, {0.03})});
  const BlendBudget b = Budget({Make("sample_signal", Sharing::kIndependent, 0, {0.04})});
  const std::vector<BlendVertex> v = {{1, 0.5, &a}, {2, 0.5, &b}};
  Result<BlendedUncertainty> u = BlendMeasurementUncertainty(v, 1);
  ASSERT_TRUE(u.ok());
  EXPECT_NEAR(u->measurement[0], std::hypot(0.5 * 0.03, 0.5 * 0.04), 1e-15);
  EXPECT_EQ(u->shared[0], 0.0);
}

TEST(BlendUncertainty, DifferentReferencesDoNotCorrelateButTheSameOneDoes) {
  // reference_signal shared through reference 10 by vertices 1 and 2, through 11 by vertex 3.
  const BlendBudget a = Budget({Make("reference_signal", Sharing::kReferenceReading, 10, {-0.01})});
  const BlendBudget b = Budget({Make("reference_signal", Sharing::kReferenceReading, 10, {-0.02})});
  const BlendBudget c = Budget({Make("reference_signal", Sharing::kReferenceReading, 11, {-0.03})});
  const std::vector<BlendVertex> v = {{1, 0.2, &a}, {2, 0.3, &b}, {3, 0.5, &c}};
  Result<BlendedUncertainty> u = BlendMeasurementUncertainty(v, 1);
  ASSERT_TRUE(u.ok());
  const double same = 0.2 * F(-0.01) + 0.3 * F(-0.02);
  EXPECT_NEAR(u->measurement[0], std::hypot(same, 0.5 * F(-0.03)), 1e-15);
}

TEST(BlendUncertainty, SignedContributionsOfOneInputCancel) {
  // The lamp drift seen with opposite signs by two readings of one reference interval: a blend
  // in the middle cancels it, as the covariance of a linear drift says.
  const BlendBudget a = Budget({Make("lamp_drift", Sharing::kReferenceReading, 4, {0.01})});
  const BlendBudget b = Budget({Make("lamp_drift", Sharing::kReferenceReading, 4, {-0.01})});
  const std::vector<BlendVertex> v = {{1, 0.5, &a}, {2, 0.5, &b}};
  Result<BlendedUncertainty> u = BlendMeasurementUncertainty(v, 1);
  ASSERT_TRUE(u.ok());
  EXPECT_NEAR(u->measurement[0], 0.0, 1e-18);
}

TEST(BlendUncertainty, SameNameThroughAnotherKindIsAnotherInput) {
  const BlendBudget a = Budget({Make("x", Sharing::kInstrument, 3, {0.01})});
  const BlendBudget b = Budget({Make("x", Sharing::kWhiteStandard, 3, {0.01})});
  const std::vector<BlendVertex> v = {{1, 0.5, &a}, {2, 0.5, &b}};
  Result<BlendedUncertainty> u = BlendMeasurementUncertainty(v, 1);
  ASSERT_TRUE(u.ok());
  EXPECT_NEAR(u->measurement[0], std::hypot(0.5 * F(0.01), 0.5 * F(0.01)), 1e-15);
}

TEST(BlendUncertainty, AReadingBlendedTwiceIsOneReading) {
  // A mirrored copy keeps its reading's id: its independent noise is the same draw.
  const BlendBudget a = Budget({Make("sample_signal", Sharing::kIndependent, 0, {0.02})});
  const std::vector<BlendVertex> v = {{1, 0.5, &a}, {1, 0.5, &a}};
  Result<BlendedUncertainty> u = BlendMeasurementUncertainty(v, 1);
  ASSERT_TRUE(u.ok());
  EXPECT_NEAR(u->measurement[0], 0.02, 1e-15);
}

TEST(BlendUncertainty, AVertexWithoutABudgetIsNamedNotCountedAsZero) {
  ReadingBudget whole = WholeBudget({Make("sample_signal", Sharing::kIndependent, 0, {0.02})});
  whole.not_estimated = {"pose_repeatability: no gradient yet"};
  const BlendBudget a = Blendable(whole), b = Blendable(whole);
  const std::vector<BlendVertex> v = {{1, 0.5, &a}, {2, 0.25, &b}, {3, 0.25, nullptr}};
  Result<BlendedUncertainty> u = BlendMeasurementUncertainty(v, 1);
  ASSERT_TRUE(u.ok());
  EXPECT_NEAR(u->measurement[0], std::hypot(0.01, 0.005), 1e-15);
  ASSERT_EQ(u->not_estimated.size(), 2u);  // the pose once, and reading 3
  EXPECT_EQ(u->not_estimated[0], "pose_repeatability: no gradient yet");
  EXPECT_NE(u->not_estimated[1].find("reading 3"), std::string::npos);
  EXPECT_NE(u->not_estimated[1].find("not estimated"), std::string::npos);
}

TEST(BlendUncertainty, MixedTermsCombineByGum52) {
  // Both vertices: an independent signal term, the white standard (shared), and each its own dark.
  const ReadingBudget whole_a =
      WholeBudget({Make("sample_signal", Sharing::kIndependent, 0, {0.03}),
                   Make("white_standard", Sharing::kWhiteStandard, 9, {0.05}),
                   Make("dark_signal", Sharing::kDarkReading, 20, {0.01})});
  const ReadingBudget whole_b =
      WholeBudget({Make("sample_signal", Sharing::kIndependent, 0, {0.01}),
                   Make("white_standard", Sharing::kWhiteStandard, 9, {0.07}),
                   Make("dark_signal", Sharing::kDarkReading, 21, {0.02})});
  const BlendBudget a = Blendable(whole_a), b = Blendable(whole_b);
  const std::vector<BlendVertex> v = {{1, 0.6, &a}, {2, 0.4, &b}};
  Result<BlendedUncertainty> u = BlendMeasurementUncertainty(v, 1);
  ASSERT_TRUE(u.ok());
  const double white = 0.6 * F(0.05) + 0.4 * F(0.07);
  const double dark20 = 0.6 * F(0.01), dark21 = 0.4 * F(0.02);
  const double shared2 = white * white + dark20 * dark20 + dark21 * dark21;
  const double ind2 = 0.018 * 0.018 + 0.004 * 0.004;
  EXPECT_NEAR(u->shared[0], std::sqrt(shared2), 1e-15);
  EXPECT_NEAR(u->measurement[0], std::sqrt(shared2 + ind2), 1e-15);
  // Treating all as independent would understate it.
  EXPECT_GT(u->measurement[0], std::hypot(0.6 * whole_a.combined[0], 0.4 * whole_b.combined[0]));
}

TEST(BlendUncertainty, BadInputIsNamed) {
  const BlendBudget a = Budget({Make("sample_signal", Sharing::kIndependent, 0, {0.03, 0.01})});
  const std::vector<BlendVertex> wrong_bands = {{5, 1.0, &a}};
  Result<BlendedUncertainty> u = BlendMeasurementUncertainty(wrong_bands, 3);
  ASSERT_FALSE(u.ok());
  EXPECT_NE(u.status().message().find("reading 5"), std::string::npos);
  const std::vector<BlendVertex> nan_weight = {{6, std::nan(""), &a}};
  EXPECT_FALSE(BlendMeasurementUncertainty(nan_weight, 2).ok());
  EXPECT_FALSE(BlendMeasurementUncertainty(nan_weight, 0).ok());
}

// A reading's budget over `bands` bands: an independent term, the session's white standard, its
// own reference (`reference`) and the instrument's wavelength scale, each a different spectrum.
ReadingBudget ManyBands(std::size_t bands, std::int64_t reference, double scale) {
  std::vector<double> signal(bands), white(bands), ref(bands), wavelength(bands);
  for (std::size_t k = 0; k < bands; ++k) {
    const double x = static_cast<double>(k);
    signal[k] = scale * (0.01 + 0.0001 * x);
    white[k] = scale * (0.02 + 0.00005 * x);
    ref[k] = -scale * (0.005 + 0.00003 * x);
    wavelength[k] = scale * 0.001 * std::sin(0.1 * x);
  }
  return WholeBudget({Make("sample_signal", Sharing::kIndependent, 0, signal),
                      Make("white_standard", Sharing::kWhiteStandard, 1, white),
                      Make("reference_signal", Sharing::kReferenceReading, reference, ref),
                      Make("wavelength_scale", Sharing::kInstrument, 1, wavelength)});
}

TEST(BlendUncertainty, EveryBandOfALongGridFollowsGum52AndBlendsDoNotLeakIntoTheNext) {
  // 101 and 401 bands (the PR-650's and the CS-2000's grids): every band, the last ones after the
  // vectors' full widths included, is the GUM §5.2 sum written out here; a blend of other
  // vertices in between (the same thread's scratch) changes nothing.
  for (std::size_t n : {std::size_t{101}, std::size_t{401}}) {
    const ReadingBudget wa = ManyBands(n, 10, 1.0), wb = ManyBands(n, 10, 1.3),
                        wc = ManyBands(n, 11, 0.7);
    const BlendBudget a = Blendable(wa), b = Blendable(wb), c = Blendable(wc);
    const std::vector<BlendVertex> v = {{1, 0.2, &a}, {2, 0.5, &b}, {3, 0.3, &c}};
    const int bands = static_cast<int>(n);
    Result<BlendedUncertainty> first = BlendMeasurementUncertainty(v, bands);
    ASSERT_TRUE(first.ok()) << first.status().message();
    const std::vector<BlendVertex> other = {{4, 1.0, &c}};
    ASSERT_TRUE(BlendMeasurementUncertainty(other, bands).ok());
    Result<BlendedUncertainty> again = BlendMeasurementUncertainty(v, bands);
    ASSERT_TRUE(again.ok());
    EXPECT_EQ(again->measurement, first->measurement);
    EXPECT_EQ(again->shared, first->shared);
    for (std::size_t k = 0; k < n; ++k) {
      // Component 0 is independent (a double), the others shared (floats).
      auto u = [&](const ReadingBudget& r, int j) {
        const double x = r.components[j].contribution[k];
        return j == 0 ? x : F(x);
      };
      const double white = 0.2 * u(wa, 1) + 0.5 * u(wb, 1) + 0.3 * u(wc, 1);
      const double ref10 = 0.2 * u(wa, 2) + 0.5 * u(wb, 2);
      const double ref11 = 0.3 * u(wc, 2);
      const double wl = 0.2 * u(wa, 3) + 0.5 * u(wb, 3) + 0.3 * u(wc, 3);
      const double shared2 = white * white + ref10 * ref10 + ref11 * ref11 + wl * wl;
      const double ind2 =
          0.04 * u(wa, 0) * u(wa, 0) + 0.25 * u(wb, 0) * u(wb, 0) + 0.09 * u(wc, 0) * u(wc, 0);
      EXPECT_NEAR(first->shared[k], std::sqrt(shared2), 1e-15) << "band " << k << " of " << n;
      EXPECT_NEAR(first->measurement[k], std::sqrt(shared2 + ind2), 1e-15)
          << "band " << k << " of " << n;
    }
  }
}

TEST(BlendUncertainty, IntoAReusedResultGivesTheSameAsAFreshOne) {
  // A batch blends answer after answer into one BlendedUncertainty: whatever it held before (a
  // longer grid, other not-estimated entries) is replaced.
  const BlendBudget a = Blendable(ManyBands(401, 10, 1.0)), b = Blendable(ManyBands(101, 10, 1.0)),
                    c = Blendable(ManyBands(101, 11, 0.5));
  BlendedUncertainty reused;
  const std::vector<BlendVertex> long_grid = {{1, 1.0, &a}, {2, 0.0, nullptr}};
  ASSERT_TRUE(BlendMeasurementUncertainty(long_grid, 401, &reused).ok());
  ASSERT_EQ(reused.measurement.size(), 401u);
  ASSERT_EQ(reused.not_estimated.size(), 1u);  // reading 2
  const std::vector<BlendVertex> v = {{3, 0.4, &b}, {4, 0.6, &c}};
  ASSERT_TRUE(BlendMeasurementUncertainty(v, 101, &reused).ok());
  Result<BlendedUncertainty> fresh = BlendMeasurementUncertainty(v, 101);
  ASSERT_TRUE(fresh.ok());
  EXPECT_EQ(reused.measurement, fresh->measurement);
  EXPECT_EQ(reused.shared, fresh->shared);
  EXPECT_EQ(reused.not_estimated, fresh->not_estimated);
  EXPECT_TRUE(reused.not_estimated.empty());
}

// The names budget.cc gives shared components have fixed codes (no table grows for a session's
// budgets); another name gets the next code of the table that met it, and a copy of that table
// codes what it holds alike.
TEST(BlendBudget, SharedNamesHaveFixedCodesAndOthersExtendTheirTable) {
  BudgetInputs in;
  in.session_id = 7;
  in.grid = WavelengthGrid{500, 4, 3};
  in.sample = MeasuredSignal{13, {0.05, 0.06, 0.07}, 1000, 4};
  in.reference = MeasuredSignal{11, {0.201, 0.201, 0.201}, 1000, 4};
  in.dark = MeasuredSignal{12, {0.001, 0.001, 0.001}, 1000, 4};
  in.white_reflectance = {0.99};
  in.white_reflectance_u = {0.005};
  in.theta_i_deg = 30;
  in.theta_r_deg = 5;
  in.drift = LampDrift{0.01, 0.5};
  in.terms.stray_light = 0.001;
  in.terms.stage.alignment_deg = {0.1, 0.1, 0.1, 0.1};
  in.pose_gradient = std::array<std::vector<double>, 4>{
      std::vector<double>{0.1, 0.2, 0.3}, std::vector<double>{0.1, 0.2, 0.3},
      std::vector<double>{0.1, 0.2, 0.3}, std::vector<double>{0.1, 0.2, 0.3}};
  Result<ReadingBudget> whole = EstimateReadingBudget(in);
  ASSERT_TRUE(whole.ok()) << whole.status().message();
  NameCodes codes;
  Result<BlendBudget> b = ToBlendBudget(*whole, codes);
  ASSERT_TRUE(b.ok()) << b.status().message();
  EXPECT_EQ(b->keys.size(), std::size(kSharedComponentNames));  // every shared name, once
  EXPECT_EQ(codes.others(), 0u);
  EXPECT_EQ(codes.Code("white_standard"), 2u);
  const std::uint32_t first = codes.Code("a_new_term");
  EXPECT_EQ(first, std::size(kSharedComponentNames));
  NameCodes copy = codes;
  EXPECT_EQ(copy.Code("a_new_term"), first);
  EXPECT_EQ(codes.Code("another_term"), first + 1);
  EXPECT_EQ(codes.Code("a_new_term"), first);
  EXPECT_EQ(codes.others(), 2u);
}

TEST(InterpolationSpread, EveryBandOfALongGrid) {
  const std::size_t n = 101;
  std::vector<double> f1(n), f2(n), f3(n), blend(n);
  const std::vector<double> w = {0.5, 0.3, 0.2};
  for (std::size_t k = 0; k < n; ++k) {
    f1[k] = 1.0 + 0.01 * static_cast<double>(k);
    f2[k] = 2.0 - 0.005 * static_cast<double>(k);
    f3[k] = 0.5 + 0.02 * static_cast<double>(k % 7);
    blend[k] = w[0] * f1[k] + w[1] * f2[k] + w[2] * f3[k];
  }
  const std::vector<std::span<const double>> spectra = {f1, f2, f3};
  const std::vector<double> u = InterpolationSpread(w, spectra, blend);
  ASSERT_EQ(u.size(), n);
  std::vector<double> reused(401, 7.0);  // a longer answer's spread before: replaced
  InterpolationSpread(w, spectra, blend, &reused);
  EXPECT_EQ(reused, u);
  for (std::size_t k = 0; k < n; ++k) {
    const double d1 = f1[k] - blend[k], d2 = f2[k] - blend[k], d3 = f3[k] - blend[k];
    EXPECT_NEAR(u[k], std::sqrt(0.5 * d1 * d1 + 0.3 * d2 * d2 + 0.2 * d3 * d3), 1e-14)
        << "band " << k;
  }
}

TEST(InterpolationSpread, ZeroAtAReadingAndTheWeightedSpreadElsewhere) {
  const std::vector<double> f1 = {1.0, 2.0};
  const std::vector<double> f2 = {3.0, 2.0};
  const std::vector<std::span<const double>> spectra = {f1, f2};
  const std::vector<double> at_reading = {1.0, 0.0};
  EXPECT_EQ(InterpolationSpread(at_reading, spectra, f1), (std::vector<double>{0.0, 0.0}));
  const std::vector<double> half = {0.5, 0.5};
  const std::vector<double> blend = {2.0, 2.0};
  const std::vector<double> u = InterpolationSpread(half, spectra, blend);
  EXPECT_NEAR(u[0], 1.0, 1e-15);  // sqrt(0.5·1 + 0.5·1)
  EXPECT_EQ(u[1], 0.0);           // the vertices agree in this band
}

}  // namespace
}  // namespace brdf::uncertainty
