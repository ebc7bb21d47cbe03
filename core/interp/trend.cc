#include "core/interp/trend.h"

#include <algorithm>
#include <cmath>
#include <initializer_list>
#include <string>

#include "core/interp/half_difference.h"

namespace brdf::interp {
namespace {

// Where the lobe is (a few degrees of θh) the knots are 1° apart; Fresnel and the rest vary
// slowly with θd.
std::vector<double> ThetaHalfKnots() {
  std::vector<double> k;
  for (int h = 0; h <= 16; ++h) k.push_back(h);
  for (double h : {18.0, 20.0, 24.0, 28.0, 32.0, 40.0, 50.0, 60.0, 70.0, 80.0, 90.0}) {
    k.push_back(h);
  }
  return k;
}

std::vector<double> ThetaDiffKnots() {
  std::vector<double> k;
  for (int d = 0; d <= 90; d += 5) k.push_back(d);
  return k;
}

// The cell of `knots` holding x (clamped to the ends) and x's fraction across it.
std::pair<std::size_t, double> Locate(const std::vector<double>& knots, double x) {
  const auto upper = std::upper_bound(knots.begin(), knots.end(), x);
  std::size_t cell =
      upper == knots.begin() ? 0 : static_cast<std::size_t>(upper - knots.begin()) - 1;
  cell = std::min(cell, knots.size() - 2);
  const double t = (x - knots[cell]) / (knots[cell + 1] - knots[cell]);
  return {cell, std::clamp(t, 0.0, 1.0)};
}

// The four knots (indices into the h × d grid) and bilinear weights of (θh, θd).
struct Stencil {
  std::size_t knot[4];
  double weight[4];
};

Stencil StencilAt(const std::vector<double>& kh, const std::vector<double>& kd,
                  std::span<const double> iso) {
  const HalfDiffAngles hd = ToHalfDifference({iso[0], iso[1], iso[2]});
  const auto [i, s] = Locate(kh, std::isfinite(hd.theta_h) ? hd.theta_h : 0.0);
  const auto [j, t] = Locate(kd, std::isfinite(hd.theta_d) ? hd.theta_d : 0.0);
  const std::size_t nd = kd.size();
  return {{i * nd + j, (i + 1) * nd + j, i * nd + j + 1, (i + 1) * nd + j + 1},
          {(1 - s) * (1 - t), s * (1 - t), (1 - s) * t, s * t}};
}

// Cholesky of the symmetric positive definite n × n matrix `a` (row-major, nonzero only within
// `band` of the diagonal), in place, then solves a · x = b for `columns` right-hand sides stored
// as b[row * columns + c].
void SolveBandedSpd(std::vector<double>& a, std::size_t n, std::size_t band, std::vector<double>& b,
                    std::size_t columns) {
  for (std::size_t j = 0; j < n; ++j) {
    const std::size_t first = j > band ? j - band : 0;
    double d = a[j * n + j];
    for (std::size_t k = first; k < j; ++k) d -= a[j * n + k] * a[j * n + k];
    d = std::sqrt(std::max(d, 1e-300));
    a[j * n + j] = d;
    for (std::size_t i = j + 1; i < std::min(n, j + band + 1); ++i) {
      double v = a[i * n + j];
      for (std::size_t k = std::max(first, i > band ? i - band : 0); k < j; ++k) {
        v -= a[i * n + k] * a[j * n + k];
      }
      a[i * n + j] = v / d;
    }
  }
  for (std::size_t i = 0; i < n; ++i) {  // L y = b, all columns at once
    double* row = &b[i * columns];
    for (std::size_t k = i > band ? i - band : 0; k < i; ++k) {
      const double l = a[i * n + k];
      const double* other = &b[k * columns];
      for (std::size_t c = 0; c < columns; ++c) row[c] -= l * other[c];
    }
    for (std::size_t c = 0; c < columns; ++c) row[c] /= a[i * n + i];
  }
  for (std::size_t i = n; i-- > 0;) {  // Lᵀ x = y
    double* row = &b[i * columns];
    for (std::size_t k = i + 1; k < std::min(n, i + band + 1); ++k) {
      const double l = a[k * n + i];
      const double* other = &b[k * columns];
      for (std::size_t c = 0; c < columns; ++c) row[c] -= l * other[c];
    }
    for (std::size_t c = 0; c < columns; ++c) row[c] /= a[i * n + i];
  }
}

// cos θi · cos θo: the trend is fitted to f · cos θi · cos θo, in which a microfacet lobe's
// D · F · G / 4 has no 1 / (cos θi cos θo) left to rise toward grazing angles.
constexpr double kMinForeshortening = 1e-4;
double Foreshortening(std::span<const double> iso) {
  constexpr double kRad = 3.14159265358979323846 / 180.0;
  return std::max(kMinForeshortening,
                  std::max(0.0, std::cos(iso[0] * kRad)) * std::max(0.0, std::cos(iso[1] * kRad)));
}

// The curvature penalty's weight against one sample's squared error: small, so that data decide
// wherever there are data, and knots without samples continue their neighbours' slopes.
constexpr double kSmoothness = 1e-2;

class TrendInterpolator final : public Interpolator {
 public:
  // `residuals_bytes`: the heap of the set of residuals `inner` was built over.
  TrendInterpolator(std::unique_ptr<Interpolator> inner, BivariateTrend trend,
                    std::size_t residuals_bytes)
      : inner_(std::move(inner)), trend_(std::move(trend)), residuals_bytes_(residuals_bytes) {}

  Method method() const override { return inner_->method(); }
  int dims() const override { return 3; }
  std::size_t HeapBytes() const override {
    return sizeof(*this) + residuals_bytes_ + trend_.HeapBytes() + inner_->HeapBytes();
  }

  Interpolation Evaluate(std::span<const double> query) const override {
    Interpolation answer = inner_->Evaluate(query);
    Finish(query, answer);
    return answer;
  }

  InterpStatus SpectrumAt(std::span<const double> query,
                          std::span<double> spectrum) const override {
    const InterpStatus status = inner_->SpectrumAt(query, spectrum);
    if (status == InterpStatus::kOk && query.size() == 3) AddTrend(query, spectrum);
    return status;
  }

  void EvaluateEach(std::span<const double> queries, const TakeAnswer& take) const override {
    inner_->EvaluateEach(queries, [&](std::size_t i, Interpolation&& answer) {
      Finish(queries.subspan(3 * i, 3), answer);
      return take(i, std::move(answer));
    });
  }

  void SpectraAt(std::span<const double> queries, std::span<InterpStatus> statuses,
                 std::span<double> spectra) const override {
    inner_->SpectraAt(queries, statuses, spectra);
    const std::size_t n = statuses.size();
    if (n == 0) return;
    const std::size_t bands = spectra.size() / n;
    for (std::size_t i = 0; i < n; ++i) {
      if (statuses[i] == InterpStatus::kOk) {
        AddTrend(queries.subspan(3 * i, 3), spectra.subspan(i * bands, bands));
      }
    }
  }

 private:
  // An answer of the inner method over the residuals, made an answer over the spectra.
  void Finish(std::span<const double> query, Interpolation& answer) const {
    if (answer.status != InterpStatus::kOk || query.size() != 3) return;
    AddTrend(query, answer.spectrum);
    answer.detail += answer.detail.empty() ? "" : "; ";
    answer.detail += "bivariate trend T(θh, θd) + the weighted residuals";
  }

  void AddTrend(std::span<const double> query, std::span<double> spectrum) const {
    thread_local std::vector<double> t;
    t.resize(static_cast<std::size_t>(trend_.bands()));
    trend_.At(query, t);
    const std::size_t n = std::min(t.size(), spectrum.size());
    for (std::size_t b = 0; b < n; ++b) spectrum[b] += t[b];
  }

  std::unique_ptr<Interpolator> inner_;
  BivariateTrend trend_;
  std::size_t residuals_bytes_;
};

}  // namespace

Result<BivariateTrend> BivariateTrend::Fit(const SampleSet& samples) {
  if (samples.dims() != 3) {
    return InvalidArgument("the bivariate trend is for isotropic (3D) data; these samples have " +
                           std::to_string(samples.dims()) + " coordinates");
  }
  if (samples.size() == 0)
    return FailedPrecondition("the bivariate trend needs samples; none given");
  BivariateTrend trend;
  trend.bands_ = samples.bands();
  trend.knots_h_ = ThetaHalfKnots();
  trend.knots_d_ = ThetaDiffKnots();
  const std::size_t nh = trend.knots_h_.size(), nd = trend.knots_d_.size(), k = nh * nd;
  // Unknowns interleaved, A then B at each knot, so that the matrix is banded.
  const std::size_t m = 2 * k;
  const std::size_t band = 4 * nd + 2;
  const auto bands = static_cast<std::size_t>(trend.bands_);
  std::vector<double> a(m * m, 0.0), rhs(m * bands, 0.0);
  for (std::size_t s = 0; s < samples.size(); ++s) {
    const Stencil st = StencilAt(trend.knots_h_, trend.knots_d_, samples.coords(s));
    const double inv_c = 1.0 / Foreshortening(samples.coords(s));
    std::size_t index[8];
    double weight[8];
    for (int u = 0; u < 4; ++u) {
      index[u] = 2 * st.knot[u];
      weight[u] = st.weight[u];
      index[4 + u] = 2 * st.knot[u] + 1;
      weight[4 + u] = st.weight[u] * inv_c;
    }
    const std::span<const double> f = samples.spectrum(s);
    for (int u = 0; u < 8; ++u) {
      for (int v = 0; v < 8; ++v) a[index[u] * m + index[v]] += weight[u] * weight[v];
      for (std::size_t b = 0; b < bands; ++b) rhs[index[u] * bands + b] += weight[u] * f[b];
    }
  }
  // λ · (Σ c_k v_k)² for a difference stencil c over unknowns p.
  auto penalize = [&](std::initializer_list<std::pair<std::size_t, double>> terms, double weight) {
    for (const auto& [p, cp] : terms) {
      for (const auto& [q, cq] : terms) a[p * m + q] += weight * cp * cq;
    }
  };
  const std::vector<double>& kh = trend.knots_h_;
  const std::vector<double>& kd = trend.knots_d_;
  for (std::size_t half = 0; half < 2; ++half) {
    for (std::size_t i = 0; i < nh; ++i) {
      for (std::size_t j = 0; j < nd; ++j) {
        const std::size_t p = 2 * (i * nd + j) + half;
        // Second differences in degrees (the knots are not evenly spaced): where no sample is,
        // the slopes carry on, and a trend linear in the angles costs nothing.
        if (i > 0 && i + 1 < nh) {
          const double h0 = kh[i] - kh[i - 1], h1 = kh[i + 1] - kh[i];
          penalize({{p - 2 * nd, 1 / h0}, {p, -1 / h0 - 1 / h1}, {p + 2 * nd, 1 / h1}},
                   kSmoothness * h0 * h1);
        }
        if (j > 0 && j + 1 < nd) {
          const double h0 = kd[j] - kd[j - 1], h1 = kd[j + 1] - kd[j];
          penalize({{p - 2, 1 / h0}, {p, -1 / h0 - 1 / h1}, {p + 2, 1 / h1}},
                   kSmoothness * h0 * h1);
        }
      }
    }
  }
  // B is also pulled gently toward 0, so that it takes only what A cannot.
  for (std::size_t p = 1; p < m; p += 2) a[p * m + p] += kSmoothness * 1e-2;
  SolveBandedSpd(a, m, band, rhs, bands);
  trend.values_ = std::move(rhs);
  return trend;
}

void BivariateTrend::At(std::span<const double> iso, std::span<double> out) const {
  const Stencil st = StencilAt(knots_h_, knots_d_, iso);
  const double inv_c = 1.0 / Foreshortening(iso);
  const auto bands = static_cast<std::size_t>(bands_);
  const std::size_t n = std::min(bands, out.size());
  for (std::size_t b = 0; b < n; ++b) {
    double v = 0, w = 0;
    for (int u = 0; u < 4; ++u) {
      v += st.weight[u] * values_[2 * st.knot[u] * bands + b];
      w += st.weight[u] * values_[(2 * st.knot[u] + 1) * bands + b];
    }
    out[b] = v + w * inv_c;
  }
}

std::shared_ptr<SampleSet> TrendResiduals(const SampleSet& samples, const BivariateTrend& trend) {
  auto out = std::make_shared<SampleSet>(samples.dims(), samples.bands());
  std::vector<double> r(static_cast<std::size_t>(samples.bands()));
  for (std::size_t i = 0; i < samples.size(); ++i) {
    trend.At(samples.coords(i), r);
    const std::span<const double> f = samples.spectrum(i);
    for (std::size_t b = 0; b < r.size(); ++b) r[b] = f[b] - r[b];
    // Same dims and bands as `samples`: Add cannot fail.
    (void)out->Add(samples.id(i), samples.coords(i), r);
  }
  return out;
}

Result<std::unique_ptr<Interpolator>> MakeTrendInterpolator(
    Method method, std::shared_ptr<const SampleSet> samples, const Options& options) {
  if (!samples) return InvalidArgument("MakeInterpolator: no sample set");
  Result<BivariateTrend> trend = BivariateTrend::Fit(*samples);
  if (!trend.ok()) return trend.status().WithContext("options.trend bivariate");
  Options inner_options = options;
  inner_options.trend = Trend::kNone;
  std::shared_ptr<SampleSet> residuals = TrendResiduals(*samples, *trend);
  const std::size_t residuals_bytes = sizeof(SampleSet) + residuals->HeapBytes();
  BRDF_ASSIGN_OR_RETURN(std::unique_ptr<Interpolator> inner,
                        MakeInterpolator(method, std::move(residuals), inner_options));
  return std::unique_ptr<Interpolator>(
      std::make_unique<TrendInterpolator>(std::move(inner), std::move(*trend), residuals_bytes));
}

}  // namespace brdf::interp
