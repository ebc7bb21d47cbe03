// core/fit with uncertainties: fits weighted by 1/u², their χ²/dof and parameter uncertainties.
// Synthetic data from a GGX model with Gaussian noise of known u must give χ²/dof ≈ 1 and the
// true parameters within their stated uncertainties; data from a model the fit cannot represent
// (a retro-reflective lobe on top) must give χ²/dof far above 1.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <numbers>
#include <random>
#include <vector>

#include "core/fit/fit.h"
#include "core/fit/fit_report.h"
#include "core/fit/fit_statistics.h"
#include "core/fit/models.h"
#include "core/geometry.h"
#include "tests/fit/fit_test_data.h"

namespace brdf::fit {
namespace {

constexpr double kAlpha = 0.25, kF0 = 0.2;

using testing::KdAt;
using testing::KsAt;
using testing::LongContext;
using testing::PaperDirections;
using testing::Retro;

// The standard uncertainty the synthetic readings are drawn with: `relative` of the value (2 %
// by default) and a floor.
double NoiseU(double f, double relative = 0.02) {
  return relative * std::abs(f) + 0.002;
}

// GGX (α = 0.25, F0 = 0.2, kd(λ), ks(λ)) plus `retro` sr⁻¹ of retro-reflection, at every
// direction, with Gaussian noise of standard deviation NoiseU(truth, relative) drawn from `seed`;
// each value carries that u.
Observations Noisy(const WavelengthGrid& grid, unsigned seed, double retro,
                   double relative = 0.02) {
  std::mt19937_64 rng(seed);
  std::normal_distribution<double> normal(0.0, 1.0);
  Observations data(grid);
  for (const IsoDirection& d : PaperDirections()) {
    std::vector<double> f(grid.count), u(grid.count);
    for (std::size_t b = 0; b < grid.count; ++b) {
      const double truth =
          CookTorranceBrdf(d, {KdAt(grid.at(b)), KsAt(grid.at(b)), kAlpha, kF0}) + Retro(d, retro);
      u[b] = NoiseU(truth, relative);
      f[b] = truth + u[b] * normal(rng);
    }
    EXPECT_TRUE(data.Add(d, f, u).ok());
  }
  return data;
}

TEST(InvertSymmetric, InvertsAPositiveDefiniteMatrixAndRefusesASingularOne) {
  const std::vector<double> a = {4, 2, 0.6, 2, 5, 1, 0.6, 1, 3};
  const std::vector<double> inv = InvertSymmetric(a, 3);
  ASSERT_EQ(inv.size(), 9u);
  for (int i = 0; i < 3; ++i) {
    for (int j = 0; j < 3; ++j) {
      double s = 0;
      for (int k = 0; k < 3; ++k) s += a[i * 3 + k] * inv[k * 3 + j];
      EXPECT_NEAR(s, i == j ? 1.0 : 0.0, 1e-12);
    }
  }
  EXPECT_TRUE(InvertSymmetric({1, 2, 2, 4}, 2).empty());
}

// InverseDiagonal skips what lies outside each row's envelope (the Cook-Torrance normal matrix's
// 2 × 2 blocks per band and its two shared rows): the same diagonal as InvertSymmetric's, bit
// for bit, for such a matrix and for a dense one; empty for a singular one.
TEST(InverseDiagonal, EqualsInvertSymmetricsDiagonalBitForBit) {
  const std::size_t bands = 40, n = 2 * bands + 2;
  std::vector<double> arrow(n * n, 0.0);
  for (std::size_t b = 0; b < bands; ++b) {
    const std::size_t at[4] = {2 * b, 2 * b + 1, n - 2, n - 1};
    const double x = 1.0 + 0.37 * static_cast<double>(b);
    const double g[16] = {3 * x, x,   0.2, 0.1,  x,   2 * x, 0.3,  -0.2,
                          0.2,   0.3, 0.9, 0.05, 0.1, -0.2,  0.05, 0.7};
    for (int p = 0; p < 4; ++p) {
      for (int q = 0; q < 4; ++q) arrow[at[p] * n + at[q]] += g[p * 4 + q];
    }
  }
  const std::vector<double> dense = {4, 2, 0.6, 2, 5, 1, 0.6, 1, 3};
  for (const auto& [a, size] : {std::pair{arrow, n}, std::pair{dense, std::size_t{3}}}) {
    const std::vector<double> full = InvertSymmetric(a, size);
    const std::vector<double> diagonal = InverseDiagonal(a, size);
    ASSERT_EQ(full.size(), size * size);
    ASSERT_EQ(diagonal.size(), size);
    for (std::size_t i = 0; i < size; ++i) EXPECT_EQ(diagonal[i], full[i * size + i]) << i;
  }
  EXPECT_TRUE(InverseDiagonal({1, 2, 2, 4}, 2).empty());
}

// χ²/dof of a correct model follows χ²(ν)/ν: mean 1, standard deviation √(2/ν). With ν ≈ 17,000
// (2,153 directions × 8 bands − 18 parameters) that is 0.011; the tolerance is 5 of them, so a
// correct fit fails by chance with probability < 10⁻⁶ per repetition.
TEST(WeightedFit, GgxDataWithKnownNoiseGiveChiSquarePerDofNearOneAndHonestUncertainties) {
  const WavelengthGrid grid{400, 50, 8};
  double pull2 = 0, chi2_sum = 0, dof = 0;
  std::size_t pulls = 0, inside2 = 0;
  const unsigned repetitions = 6;
  for (unsigned seed = 1; seed <= repetitions; ++seed) {
    const Observations data = Noisy(grid, seed, 0.0);
    ASSERT_TRUE(data.weighted());
    Result<CookTorranceFit> fit = FitCookTorrance(data, {}, LongContext());
    ASSERT_TRUE(fit.ok()) << fit.status().ToString();
    const FitStatistics& st = fit->statistics;
    EXPECT_TRUE(st.weighted);
    EXPECT_FALSE(st.covariance_scaled);
    EXPECT_EQ(st.parameters, 2 * grid.count + 2);
    EXPECT_EQ(st.values, data.size() * grid.count);
    EXPECT_DOUBLE_EQ(st.dof, static_cast<double>(st.values - st.parameters));
    EXPECT_NEAR(st.chi2_per_dof, 1.0, 5 * std::sqrt(2 / st.dof)) << "seed " << seed;
    chi2_sum += st.chi2_per_dof;
    dof = st.dof;
    std::printf("seed %u: χ²/dof = %.4f (ν = %.0f), α = %.5f ± %.5f, F0 = %.4f ± %.4f\n", seed,
                st.chi2_per_dof, st.dof, fit->band[0].alpha, fit->band_u[0].alpha, fit->band[0].f0,
                fit->band_u[0].f0);
    // The shared shape parameters: within 3 u in every repetition.
    EXPECT_NEAR(fit->band[0].alpha, kAlpha, 3 * fit->band_u[0].alpha) << "seed " << seed;
    EXPECT_NEAR(fit->band[0].f0, kF0, 3 * fit->band_u[0].f0) << "seed " << seed;
    // Every parameter's normalised error (pull), pooled over bands and repetitions.
    for (std::size_t b = 0; b < grid.count; ++b) {
      const CookTorranceParams& p = fit->band[b];
      const CookTorranceParams& u = fit->band_u[b];
      ASSERT_GT(u.kd, 0);
      ASSERT_GT(u.ks, 0);
      const double z[2] = {(p.kd - KdAt(grid.at(b))) / u.kd, (p.ks - KsAt(grid.at(b))) / u.ks};
      for (double v : z) {
        pull2 += v * v;
        ++pulls;
        if (std::abs(v) < 2) ++inside2;
      }
    }
    const double z[2] = {(fit->band[0].alpha - kAlpha) / fit->band_u[0].alpha,
                         (fit->band[0].f0 - kF0) / fit->band_u[0].f0};
    for (double v : z) {
      pull2 += v * v;
      ++pulls;
      if (std::abs(v) < 2) ++inside2;
    }
  }
  // The mean of the repetitions' χ²/dof: standard deviation √(2 / (6 ν)) = 0.0044; 4 of them.
  const double mean = chi2_sum / repetitions;
  std::printf("mean χ²/dof over %u seeds: %.4f\n", repetitions, mean);
  EXPECT_NEAR(mean, 1.0, 4 * std::sqrt(2 / (repetitions * dof)));
  // 108 pulls: their RMS is 1 ± 0.07 (1/√(2·108)) for honest uncertainties; ±0.25 is > 3.5σ
  // (the pulls of one fit are correlated, which widens the spread a little). At |z| < 2, 95.4 %
  // are expected; 85 % is 4.5σ of a binomial below.
  const double rms_pull = std::sqrt(pull2 / static_cast<double>(pulls));
  const double within = static_cast<double>(inside2) / static_cast<double>(pulls);
  std::printf("pulls: %zu, RMS %.3f, |z| < 2: %.1f %%\n", pulls, rms_pull, 100 * within);
  EXPECT_NEAR(rms_pull, 1.0, 0.25);
  EXPECT_GT(within, 0.85);
}

TEST(WeightedFit, PerBandSharingCountsFourParametersPerBand) {
  const WavelengthGrid grid{450, 100, 3};
  const Observations data = Noisy(grid, 11, 0.0);
  CookTorranceOptions options;
  options.sharing = ParameterSharing::kPerBand;
  Result<CookTorranceFit> fit = FitCookTorrance(data, options, LongContext());
  ASSERT_TRUE(fit.ok()) << fit.status().ToString();
  EXPECT_EQ(fit->statistics.parameters, 4 * grid.count);
  EXPECT_NEAR(fit->statistics.chi2_per_dof, 1.0, 5 * std::sqrt(2 / fit->statistics.dof));
  for (std::size_t b = 0; b < grid.count; ++b) {
    EXPECT_NEAR(fit->band[b].alpha, kAlpha, 3 * fit->band_u[b].alpha) << b;
    EXPECT_NEAR(fit->band[b].ks, KsAt(grid.at(b)), 3 * fit->band_u[b].ks) << b;
  }
}

TEST(WeightedFit, AModelTheFitCannotRepresentGivesChiSquarePerDofWellAboveOne) {
  // A retro-reflective lobe of 0.2 sr⁻¹ on the same GGX surface, the same noise: Cook-Torrance
  // and Lambert have no lobe toward the lamp, so the residuals are far larger than u.
  const WavelengthGrid grid{400, 50, 8};
  const Observations data = Noisy(grid, 7, 0.2);
  Result<CookTorranceFit> ct = FitCookTorrance(data, {}, LongContext());
  ASSERT_TRUE(ct.ok()) << ct.status().ToString();
  Result<LambertFit> lambert = FitLambert(data);
  ASSERT_TRUE(lambert.ok());
  std::printf("retro-reflective sample: Cook-Torrance χ²/dof = %.1f, Lambert χ²/dof = %.1f\n",
              ct->statistics.chi2_per_dof, lambert->statistics.chi2_per_dof);
  EXPECT_GT(ct->statistics.chi2_per_dof, 5.0);
  EXPECT_GT(lambert->statistics.chi2_per_dof, ct->statistics.chi2_per_dof);
  // The report says so, with the parameters' uncertainties in their own columns.
  const std::string csv = FitReportCsv({1, "retro", data.size(), 0, data.size()}, &*lambert, &*ct);
  EXPECT_NE(csv.find("# weighting: weighted, independent: every value by 1/u²"), std::string::npos);
  EXPECT_NE(csv.find("χ²/dof = " + std::to_string(ct->statistics.chi2_per_dof).substr(0, 2)),
            std::string::npos);
  EXPECT_NE(csv.find("lambert_albedo,lambert_albedo_u,"), std::string::npos);
  EXPECT_NE(csv.find(",ct_alpha,ct_alpha_u,ct_f0,ct_f0_u,"), std::string::npos);
  EXPECT_NE(FitSummary(nullptr, &*ct).find("χ²/dof = "), std::string::npos);
}

TEST(WeightedFit, LambertOnALambertianSurfaceWithKnownNoise) {
  const WavelengthGrid grid{400, 25, 12};
  std::mt19937_64 rng(3);
  std::normal_distribution<double> normal(0.0, 1.0);
  Observations data(grid);
  for (const IsoDirection& d : PaperDirections()) {
    std::vector<double> f(grid.count), u(grid.count);
    for (std::size_t b = 0; b < grid.count; ++b) {
      const double truth = LambertBrdf(KdAt(grid.at(b)));
      u[b] = NoiseU(truth) * (1 + d.theta_o / 90);  // unequal weights
      f[b] = truth + u[b] * normal(rng);
    }
    ASSERT_TRUE(data.Add(d, f, u).ok());
  }
  Result<LambertFit> fit = FitLambert(data);
  ASSERT_TRUE(fit.ok());
  EXPECT_EQ(fit->statistics.parameters, grid.count);
  EXPECT_NEAR(fit->statistics.chi2_per_dof, 1.0, 5 * std::sqrt(2 / fit->statistics.dof));
  for (std::size_t b = 0; b < grid.count; ++b) {
    EXPECT_NEAR(fit->albedo[b], KdAt(grid.at(b)), 3 * fit->albedo_u[b]) << grid.at(b);
  }
}

TEST(WeightedFit, WithoutUncertaintiesTheFitIsUnweightedAndScalesByTheResidualVariance) {
  // One reading without a budget makes the whole fit unweighted: χ²/dof is not defined (NaN) and
  // the parameter uncertainties come from the residuals' own scatter. With noise of one size
  // everywhere (0.002 sr⁻¹) that scatter is the noise, so the scaled uncertainties equal the
  // weighted fit's times √(χ²/dof). (With noise that grows with f, as real readings have, the
  // unweighted fit's scaled uncertainties are not to be trusted: the reason to weight.)
  const WavelengthGrid grid{400, 100, 4};
  const Observations noisy = Noisy(grid, 5, 0.0, 0.0);
  Observations data(grid);
  for (std::size_t i = 0; i < noisy.size(); ++i) {
    std::vector<double> u(grid.count);
    for (std::size_t b = 0; b < grid.count; ++b) u[b] = noisy.uncertainty(i, b);
    ASSERT_TRUE(data.Add(noisy.direction(i), noisy.spectrum(i),
                         i == 0 ? std::span<const double>() : std::span<const double>(u))
                    .ok());
  }
  EXPECT_FALSE(data.weighted());
  EXPECT_EQ(data.with_uncertainty(), data.size() - 1);
  Result<CookTorranceFit> fit = FitCookTorrance(data, {}, LongContext());
  Result<CookTorranceFit> weighted = FitCookTorrance(noisy, {}, LongContext());
  ASSERT_TRUE(fit.ok());
  ASSERT_TRUE(weighted.ok());
  EXPECT_FALSE(fit->statistics.weighted);
  EXPECT_TRUE(fit->statistics.covariance_scaled);
  EXPECT_TRUE(std::isnan(fit->statistics.chi2_per_dof));
  const std::string csv =
      FitReportCsv({1, "", data.size(), 0, data.with_uncertainty()}, nullptr, &*fit);
  EXPECT_NE(csv.find("# weighting: none, every value alike (" + std::to_string(data.size() - 1) +
                     " of " + std::to_string(data.size())),
            std::string::npos);
  EXPECT_NE(csv.find("χ²/dof: none"), std::string::npos);
  EXPECT_NEAR(fit->band[0].alpha, kAlpha, 3 * fit->band_u[0].alpha);
  const double birge = std::sqrt(weighted->statistics.chi2_per_dof);
  EXPECT_NEAR(fit->band_u[0].alpha, weighted->band_u[0].alpha * birge, 0.01 * fit->band_u[0].alpha);
  EXPECT_NEAR(fit->band_u[2].kd, weighted->band_u[2].kd * birge, 0.01 * fit->band_u[2].kd);
}

TEST(Observations, RejectsUncertaintiesThatCannotWeigh) {
  Observations data({400, 100, 2});
  EXPECT_EQ(data.Add({10, 10, 0}, std::vector<double>{1, 1}, std::vector<double>{0.1}).code(),
            StatusCode::kInvalidArgument);
  EXPECT_EQ(data.Add({10, 10, 0}, std::vector<double>{1, 1}, std::vector<double>{0.1, 0}).code(),
            StatusCode::kInvalidArgument);
  EXPECT_EQ(data.Add({10, 10, 0}, std::vector<double>{1, 1}, std::vector<double>{NAN, 0.1}).code(),
            StatusCode::kInvalidArgument);
  EXPECT_EQ(data.size(), 0u);
  EXPECT_FALSE(data.weighted());
}

}  // namespace
}  // namespace brdf::fit
