#include "core/fit/band_covariance.h"

#include <cmath>
#include <cstdint>
#include <string>

#include "core/fit/fit_statistics.h"

namespace brdf::fit {

namespace {

// The fraction contribution / value of `source` in every band when it is the same for every
// observation (to 1e-9, bands where both are 0 aside) and every observation names it; else empty.
std::vector<double> ScaleFractions(const Observations& data, std::size_t source) {
  std::vector<double> fraction(data.bands(), std::nan(""));
  for (std::size_t i = 0; i < data.size(); ++i) {
    const SharedTerm* term = nullptr;
    for (const SharedTerm& t : data.shared(i)) {
      if (t.source == source) term = &t;
    }
    if (term == nullptr) return {};
    for (std::size_t b = 0; b < data.bands(); ++b) {
      const double c = term->contribution[b], f = data.value(i, b);
      if (c == 0 && f == 0) continue;
      if (f == 0) return {};
      if (std::isnan(fraction[b])) fraction[b] = c / f;
      if (std::abs(c / f - fraction[b]) > 1e-9 * std::abs(fraction[b])) return {};
    }
  }
  for (double& x : fraction) {
    if (std::isnan(x)) x = 0;
  }
  return fraction;
}

}  // namespace

std::vector<ScaleSource> ScaleSourcesOf(const Observations& data) {
  std::vector<ScaleSource> scales;
  if (data.weighting() != Weighting::kGeneralised) return scales;
  for (std::size_t s = 0; s < data.shared_sources().size(); ++s) {
    std::vector<double> fraction = ScaleFractions(data, s);
    if (!fraction.empty()) scales.push_back({s, std::move(fraction)});
  }
  return scales;
}

Result<BandCovariance> BandCovariance::Of(const Observations& data, std::size_t band,
                                          const std::vector<ScaleSource>& leave_out) {
  BandCovariance v;
  const std::size_t n = data.size();
  const bool weighted = data.weighted();
  v.inv_d_.resize(n, 1.0);
  v.offsets_.assign(1, 0);
  std::vector<std::size_t> column(data.shared_sources().size(), SIZE_MAX);
  std::vector<bool> left_out(data.shared_sources().size(), false);
  for (const ScaleSource& s : leave_out) left_out[s.source] = true;
  for (std::size_t i = 0; i < n; ++i) {
    if (weighted) {
      const double u = data.independent_uncertainty(i, band);
      v.inv_d_[i] = 1.0 / (u * u);
      for (const SharedTerm& t : data.shared(i)) {
        const double c = t.contribution[band];
        if (c == 0 || left_out[t.source]) continue;
        if (column[t.source] == SIZE_MAX) column[t.source] = v.k_++;
        v.entries_.push_back({column[t.source], c});
      }
    }
    v.offsets_.push_back(v.entries_.size());
  }
  const std::size_t k = v.k_;
  std::vector<double> m(k * k, 0.0);
  for (std::size_t j = 0; j < k; ++j) m[j * k + j] = 1.0;
  for (std::size_t i = 0; i < n; ++i) {
    for (std::size_t p = v.offsets_[i]; p < v.offsets_[i + 1]; ++p) {
      for (std::size_t q = v.offsets_[i]; q < v.offsets_[i + 1]; ++q) {
        m[v.entries_[p].column * k + v.entries_[q].column] +=
            v.entries_[p].value * v.entries_[q].value * v.inv_d_[i];
      }
    }
  }
  v.chol_ = CholeskyLower(std::move(m), k);
  if (k > 0 && v.chol_.empty()) {
    return FailedPrecondition("the covariance of the values at " +
                              std::to_string(data.grid().at(band)) +
                              " nm is not positive definite (shared contributions out of scale "
                              "with the independent parts)");
  }
  return v;
}

std::vector<double> BandCovariance::Project(std::span<const double> x) const {
  std::vector<double> z(k_, 0.0);
  if (k_ == 0) return z;
  for (std::size_t i = 0; i < inv_d_.size(); ++i) {
    const double xd = x[i] * inv_d_[i];
    for (std::size_t p = offsets_[i]; p < offsets_[i + 1]; ++p) {
      z[entries_[p].column] += entries_[p].value * xd;
    }
  }
  for (std::size_t r = 0; r < k_; ++r) {  // L z = p
    double s = z[r];
    for (std::size_t c = 0; c < r; ++c) s -= chol_[r * k_ + c] * z[c];
    z[r] = s / chol_[r * k_ + r];
  }
  return z;
}

std::vector<double> BandCovariance::Solve(std::span<const double> y) const {
  std::vector<double> w = Project(y);
  for (std::size_t r = k_; r-- > 0;) {  // Lᵀ w = z: w = M⁻¹ Bᵀ D⁻¹ y
    double s = w[r];
    for (std::size_t c = r + 1; c < k_; ++c) s -= chol_[c * k_ + r] * w[c];
    w[r] = s / chol_[r * k_ + r];
  }
  std::vector<double> out(inv_d_.size());
  for (std::size_t i = 0; i < inv_d_.size(); ++i) {
    double bw = 0;
    for (std::size_t p = offsets_[i]; p < offsets_[i + 1]; ++p) {
      bw += entries_[p].value * w[entries_[p].column];
    }
    out[i] = (y[i] - bw) * inv_d_[i];
  }
  return out;
}

double BandCovariance::Product(std::span<const double> x, std::span<const double> y) const {
  double s = 0;
  for (std::size_t i = 0; i < inv_d_.size(); ++i) s += x[i] * y[i] * inv_d_[i];
  if (k_ == 0) return s;
  const std::vector<double> zx = Project(x), zy = Project(y);
  for (std::size_t j = 0; j < k_; ++j) s -= zx[j] * zy[j];
  return s;
}

std::vector<double> BandCovariance::Gram(std::span<const std::vector<double>> columns) const {
  const std::size_t m = columns.size();
  std::vector<std::vector<double>> z;
  for (const std::vector<double>& c : columns) z.push_back(Project(c));
  std::vector<double> g(m * m, 0.0);
  for (std::size_t a = 0; a < m; ++a) {
    for (std::size_t b = 0; b <= a; ++b) {
      double s = 0;
      for (std::size_t i = 0; i < inv_d_.size(); ++i)
        s += columns[a][i] * columns[b][i] * inv_d_[i];
      for (std::size_t j = 0; j < k_; ++j) s -= z[a][j] * z[b][j];
      g[a * m + b] = g[b * m + a] = s;
    }
  }
  return g;
}

Result<std::vector<BandCovariance>> CovariancesOf(const Observations& data,
                                                  const std::vector<ScaleSource>& leave_out) {
  std::vector<BandCovariance> all;
  all.reserve(data.bands());
  for (std::size_t b = 0; b < data.bands(); ++b) {
    BRDF_ASSIGN_OR_RETURN(BandCovariance v, BandCovariance::Of(data, b, leave_out));
    all.push_back(std::move(v));
  }
  return all;
}

}  // namespace brdf::fit
