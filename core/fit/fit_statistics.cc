#include "core/fit/fit_statistics.h"

#include <algorithm>
#include <cmath>
#include <limits>

namespace brdf::fit {

FitStatistics StatisticsOf(const Observations& data, double sum_of_squares, std::size_t values,
                           std::size_t parameters) {
  const bool weighted = data.weighted();
  FitStatistics s;
  s.weighted = weighted;
  s.weighting = data.weighting();
  s.shared_terms = s.weighting == Weighting::kGeneralised ? data.shared_sources().size() : 0;
  s.values = values;
  s.parameters = parameters;
  s.chi2 = sum_of_squares;
  s.dof = values > parameters ? static_cast<double>(values - parameters) : 0.0;
  s.chi2_per_dof =
      weighted && s.dof > 0 ? s.chi2 / s.dof : std::numeric_limits<double>::quiet_NaN();
  s.covariance_scaled = !weighted;
  return s;
}

std::vector<double> CholeskyLower(std::vector<double> a, std::size_t n) {
  for (std::size_t j = 0; j < n; ++j) {
    double d = a[j * n + j];
    for (std::size_t k = 0; k < j; ++k) d -= a[j * n + k] * a[j * n + k];
    if (!(d > 0) || !std::isfinite(d)) return {};
    const double l = std::sqrt(d);
    a[j * n + j] = l;
    for (std::size_t i = j + 1; i < n; ++i) {
      double s = a[i * n + j];
      for (std::size_t k = 0; k < j; ++k) s -= a[i * n + k] * a[j * n + k];
      a[i * n + j] = s / l;
    }
    for (std::size_t i = 0; i < j; ++i) a[i * n + j] = 0;
  }
  return a;
}

std::vector<double> InvertSymmetric(std::vector<double> a, std::size_t n) {
  // a = L Lᵀ, then a⁻¹ = L⁻ᵀ L⁻¹.
  a = CholeskyLower(std::move(a), n);
  if (a.empty() && n > 0) return {};
  std::vector<double> inv_l(n * n, 0.0);  // L⁻¹, lower triangular
  for (std::size_t j = 0; j < n; ++j) {
    inv_l[j * n + j] = 1.0 / a[j * n + j];
    for (std::size_t i = j + 1; i < n; ++i) {
      double s = 0;
      for (std::size_t k = j; k < i; ++k) s -= a[i * n + k] * inv_l[k * n + j];
      inv_l[i * n + j] = s / a[i * n + i];
    }
  }
  std::vector<double> inv(n * n, 0.0);
  for (std::size_t i = 0; i < n; ++i) {
    for (std::size_t j = 0; j <= i; ++j) {
      double s = 0;
      for (std::size_t k = i; k < n; ++k) s += inv_l[k * n + i] * inv_l[k * n + j];
      inv[i * n + j] = inv[j * n + i] = s;
    }
  }
  return inv;
}

namespace {

// The Cholesky factor of `a` as CholeskyLower, skipping what is 0 in every row before its first
// non-zero (a Cholesky factor keeps that envelope): the same non-zero values, to the bit, in
// about n·w² operations for rows w wide instead of n³/6. `first[i]`: row i's first non-zero.
std::vector<double> EnvelopeCholesky(std::vector<double> a, std::size_t n,
                                     const std::vector<std::size_t>& first) {
  for (std::size_t j = 0; j < n; ++j) {
    double d = a[j * n + j];
    for (std::size_t k = first[j]; k < j; ++k) d -= a[j * n + k] * a[j * n + k];
    if (!(d > 0) || !std::isfinite(d)) return {};
    const double l = std::sqrt(d);
    a[j * n + j] = l;
    for (std::size_t i = j + 1; i < n; ++i) {
      if (first[i] > j) continue;  // 0 before row i's envelope
      double s = a[i * n + j];
      for (std::size_t k = std::max(first[i], first[j]); k < j; ++k)
        s -= a[i * n + k] * a[j * n + k];
      a[i * n + j] = s / l;
    }
  }
  return a;
}

}  // namespace

std::vector<double> InverseDiagonal(std::vector<double> a, std::size_t n) {
  std::vector<std::size_t> first(n);
  for (std::size_t i = 0; i < n; ++i) {
    first[i] = i;
    for (std::size_t k = 0; k < i; ++k) {
      if (a[i * n + k] != 0) {
        first[i] = k;
        break;
      }
    }
  }
  a = EnvelopeCholesky(std::move(a), n, first);
  if (a.empty() && n > 0) return {};
  // Column j of L⁻¹ (InvertSymmetric's sums without the terms outside each row's envelope), and
  // (a⁻¹)ⱼⱼ = Σₖ (L⁻¹)ₖⱼ², k ≥ j, in InvertSymmetric's order.
  std::vector<double> diagonal(n), column(n);
  for (std::size_t j = 0; j < n; ++j) {
    column[j] = 1.0 / a[j * n + j];
    for (std::size_t i = j + 1; i < n; ++i) {
      double s = 0;
      for (std::size_t k = std::max(j, first[i]); k < i; ++k) s -= a[i * n + k] * column[k];
      column[i] = s / a[i * n + i];
    }
    double sum = 0;
    for (std::size_t k = j; k < n; ++k) sum += column[k] * column[k];
    diagonal[j] = sum;
  }
  return diagonal;
}

std::vector<double> ParameterUncertainties(const std::vector<double>& normal, std::size_t n,
                                           const std::vector<bool>& free, FitStatistics& stats) {
  std::vector<double> u(n, std::numeric_limits<double>::quiet_NaN());
  std::vector<std::size_t> index;
  for (std::size_t i = 0; i < n; ++i) {
    if (free[i]) index.push_back(i);
  }
  const std::size_t m = index.size();
  std::vector<double> block(m * m);
  for (std::size_t i = 0; i < m; ++i) {
    for (std::size_t j = 0; j < m; ++j) block[i * m + j] = normal[index[i] * n + index[j]];
  }
  const std::vector<double> cov = InverseDiagonal(std::move(block), m);
  if (cov.empty() && m > 0) {
    stats.note = "the parameters' covariance is singular (the data do not determine them all)";
    return u;
  }
  const double scale = stats.weighted ? 1.0
                                      : (stats.dof > 0 ? stats.chi2 / stats.dof
                                                       : std::numeric_limits<double>::quiet_NaN());
  for (std::size_t i = 0; i < m; ++i) u[index[i]] = std::sqrt(cov[i] * scale);
  if (m < n && stats.note.empty()) {
    stats.note =
        "parameters at a bound (kd or ks = 0, F0 = 0 or 1, α at its limit) have no uncertainty "
        "(nan): they were not free";
  }
  return u;
}

}  // namespace brdf::fit
