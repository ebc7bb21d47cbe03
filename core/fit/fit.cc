#include "core/fit/fit.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <numbers>
#include <string>

#if defined(__x86_64__)
#include <immintrin.h>
#endif

#include "core/fit/band_covariance.h"
#include "core/fit/nelder_mead.h"

namespace brdf::fit {
namespace {

constexpr double kPi = std::numbers::pi;
constexpr double kAlphaMin = 1e-4;
constexpr double kAlphaMax = 4.0;

double AlphaOf(double u) {
  return std::clamp(std::exp(u), kAlphaMin, kAlphaMax);
}
double F0Of(double v) {
  return 1.0 / (1.0 + std::exp(-v));
}
double Logit(double p) {
  p = std::clamp(p, 1e-9, 1 - 1e-9);
  return std::log(p / (1 - p));
}

// Σ of the scale sources' fraction² in `band` (band_covariance.h's ScaleSource).
double ScaleVariance(const std::vector<ScaleSource>& scales, std::size_t band) {
  double v = 0;
  for (const ScaleSource& s : scales) v += s.fraction[band] * s.fraction[band];
  return v;
}

// A linear parameter's u with the scale sources' share of its value added (NaN stays NaN).
double WithScales(double u, double value, double fraction2) {
  return std::sqrt(u * u + fraction2 * value * value);
}

// One band's values over all observations.
std::vector<double> BandValues(const Observations& data, std::size_t band) {
  std::vector<double> f(data.size());
  for (std::size_t i = 0; i < data.size(); ++i) f[i] = data.value(i, band);
  return f;
}

// One band's products under V⁻¹ for the linear part f ≈ kd·a + ks·s with a = 1/π: 1ᵀV⁻¹1,
// 1ᵀV⁻¹f, fᵀV⁻¹f (fixed) and 1ᵀV⁻¹s, sᵀV⁻¹s, sᵀV⁻¹f (for the lobe shape s being tried).
struct BandSums {
  double sw = 0, swf = 0, swff = 0;
  double sws = 0, swss = 0, swsf = 0;
};

// The best non-negative (kd, ks) for one band and its weighted sum of squared residuals.
struct LinearSolution {
  double kd = 0, ks = 0, sse = 0;
};

LinearSolution SolveBand(const BandSums& s) {
  const double a = 1.0 / kPi;
  const double saa = s.sw * a * a, sab = a * s.sws, saf = a * s.swf, sbb = s.swss, sbf = s.swsf;
  auto sse = [&](double kd, double ks) {
    return s.swff - 2 * (kd * saf + ks * sbf) + kd * kd * saa + 2 * kd * ks * sab + ks * ks * sbb;
  };
  LinearSolution best{0, 0, s.swff};
  auto consider = [&](double kd, double ks) {
    if (!(kd >= 0) || !(ks >= 0)) return;
    const double e = sse(kd, ks);
    if (e < best.sse) best = {kd, ks, e};
  };
  const double det = saa * sbb - sab * sab;
  if (det > 1e-300 * std::max(1.0, saa * sbb)) {
    consider((saf * sbb - sbf * sab) / det, (sbf * saa - saf * sab) / det);
  }
  if (saa > 0) consider(std::max(0.0, saf / saa), 0.0);
  if (sbb > 0) consider(0.0, std::max(0.0, sbf / sbb));
  best.sse = std::max(0.0, best.sse);
  return best;
}

// The observations' V⁻¹f of every band, 16 bands side by side (observation-major within each
// panel of 16 bands, the last panel padded with 0), for the lobe sums of all bands in one pass.
constexpr std::size_t kPanel = 16;
// Lobe shapes summed in one pass over the panels (the whole steps of three searches).
constexpr std::size_t kMaxShapes = 12;

// Σᵢ x_k[i] · panel[i][j] for K shapes x and the 16 bands j of one panel, into sum[k · 16 + j]:
// each band's sum over the observations in order from 0, each product rounded before it is
// added (no fused multiply-add), so every variant gives the bits of the plain scalar sum.
template <std::size_t K>
void PanelSumsScalar(const double* panel, std::size_t n, const double* const* x, double* sum) {
  std::array<double, K * kPanel> acc{};
  for (std::size_t i = 0; i < n; ++i) {
    const double* f = panel + i * kPanel;
    for (std::size_t k = 0; k < K; ++k) {
      const double xi = x[k][i];
      for (std::size_t j = 0; j < kPanel; ++j) acc[k * kPanel + j] += xi * f[j];
    }
  }
  std::copy(acc.begin(), acc.end(), sum);
}

#if defined(__x86_64__) && (defined(__GNUC__) || defined(__clang__))
template <std::size_t K>
__attribute__((target("avx512f"))) void PanelSumsAvx512(const double* panel, std::size_t n,
                                                        const double* const* x, double* sum) {
  __m512d acc[K][2];
  for (std::size_t k = 0; k < K; ++k) acc[k][0] = acc[k][1] = _mm512_setzero_pd();
  for (std::size_t i = 0; i < n; ++i) {
    const __m512d f0 = _mm512_loadu_pd(panel + i * kPanel);
    const __m512d f1 = _mm512_loadu_pd(panel + i * kPanel + 8);
#pragma GCC unroll 12
    for (std::size_t k = 0; k < K; ++k) {
      const __m512d xi = _mm512_set1_pd(x[k][i]);
      __m512d t0 = _mm512_mul_pd(xi, f0), t1 = _mm512_mul_pd(xi, f1);
      asm("" : "+v"(t0), "+v"(t1));  // round the products: no fused multiply-add
      acc[k][0] = _mm512_add_pd(acc[k][0], t0);
      acc[k][1] = _mm512_add_pd(acc[k][1], t1);
    }
  }
  for (std::size_t k = 0; k < K; ++k) {
    _mm512_storeu_pd(sum + k * kPanel, acc[k][0]);
    _mm512_storeu_pd(sum + k * kPanel + 8, acc[k][1]);
  }
}
#endif

using PanelSumsFn = void (*)(const double*, std::size_t, const double* const*, double*);

template <std::size_t K>
PanelSumsFn PickPanelSums() {
#if defined(__x86_64__) && (defined(__GNUC__) || defined(__clang__))
  if (__builtin_cpu_supports("avx512f")) return &PanelSumsAvx512<K>;
#endif
  return &PanelSumsScalar<K>;
}

// The sums for 1 ≤ k ≤ kMaxShapes shapes.
void PanelSums(const double* panel, std::size_t n, const double* const* x, std::size_t k,
               double* sum) {
  static const std::array<PanelSumsFn, kMaxShapes> pick = {
      PickPanelSums<1>(), PickPanelSums<2>(),  PickPanelSums<3>(),  PickPanelSums<4>(),
      PickPanelSums<5>(), PickPanelSums<6>(),  PickPanelSums<7>(),  PickPanelSums<8>(),
      PickPanelSums<9>(), PickPanelSums<10>(), PickPanelSums<11>(), PickPanelSums<12>()};
  pick[k - 1](panel, n, x, sum);
}

// The variable-projection objective over bands [b0, b1): evaluates the lobe shape for (α, F0)
// at every observation and solves each band's (kd, ks) under that band's V⁻¹ (V = I unweighted).
class Projection {
 public:
  Projection(const Observations& data, const std::vector<BandCovariance>& covariance,
             std::size_t b0, std::size_t b1)
      : data_(data),
        covariance_(covariance),
        b0_(b0),
        b1_(b1),
        shared_(SharedDiagonal(covariance, b0, b1)),
        sums_(b1 - b0) {
    geometry_.reserve(data.size());
    for (std::size_t i = 0; i < data.size(); ++i) {
      geometry_.push_back(LobeGeometryOf(data.direction(i)));
    }
    const std::vector<double> one(data.size(), 1.0);
    if (shared_) panels_.assign((b1 - b0 + kPanel - 1) / kPanel * kPanel * data.size(), 0.0);
    for (std::size_t b = b0; b < b1; ++b) {
      const BandCovariance& v = covariance[b];
      const std::vector<double> f = BandValues(data, b);
      std::vector<double> v_one = v.Solve(one), v_f = v.Solve(f);
      BandSums& s = sums_[b - b0];
      s.sw = Dot(one, v_one);
      s.swf = Dot(f, v_one);
      s.swff = Dot(f, v_f);
      if (shared_) {
        double* panel =
            panels_.data() + (b - b0) / kPanel * kPanel * data.size() + (b - b0) % kPanel;
        for (std::size_t i = 0; i < data.size(); ++i) panel[i * kPanel] = v_f[i];
        if (b == b0) v_one_.push_back(std::move(v_one));
      } else {
        v_one_.push_back(std::move(v_one));
        v_f_.push_back(std::move(v_f));
      }
    }
  }

  bool shared() const { return shared_; }

  // Solves for (α, F0) and returns the total (weighted) SSE; fills `out` (b1 − b0 solutions)
  // when given.
  double Evaluate(double alpha, double f0, std::vector<LinearSolution>* out) {
    const std::array<double, 2> point = {alpha, f0};
    return EvaluateAll({&point, 1}, out).front();
  }

  // Evaluate's total at each (α, F0) of `points`, the same values (`out`, when given: the last
  // point's solutions); with one diagonal V for all bands, the lobe sums of up to kMaxShapes
  // points are taken in one pass over the data.
  std::vector<double> EvaluateAll(std::span<const std::array<double, 2>> points,
                                  std::vector<LinearSolution>* out = nullptr) {
    std::vector<double> totals;
    for (std::size_t first = 0; first < points.size(); first += kMaxShapes) {
      const std::size_t k = std::min(kMaxShapes, points.size() - first);
      shapes_.resize(k * data_.size());
      for (std::size_t p = 0; p < k; ++p) {
        const auto [alpha, f0] = points[first + p];
        double* spec = shapes_.data() + p * data_.size();
        for (std::size_t i = 0; i < data_.size(); ++i) {
          spec[i] = CookTorranceSpecularAt(geometry_[i], alpha, f0);
        }
      }
      if (shared_) SharedLobeSums(k);
      for (std::size_t p = 0; p < k; ++p) {
        if (!shared_) BandLobeSums({shapes_.data() + p * data_.size(), data_.size()});
        totals.push_back(Solve(p, out));
      }
    }
    return totals;
  }

 private:
  static double Dot(std::span<const double> x, std::span<const double> y) {
    double s = 0;
    for (std::size_t i = 0; i < x.size(); ++i) s += x[i] * y[i];
    return s;
  }
  // Every band's V the same diagonal one, and at least a panel of bands (with fewer, as when
  // fitting band by band, BandLobeSums is as quick and gives the same bits).
  static bool SharedDiagonal(const std::vector<BandCovariance>& covariance, std::size_t b0,
                             std::size_t b1) {
    for (std::size_t b = b0 + 1; b < b1; ++b) {
      if (!covariance[b].SameDiagonal(covariance[b0])) return false;
    }
    return b1 >= b0 + kPanel;
  }

  // Every band's (kd, ks) for the lobe sums of shape p (shared_: shared_sums_[p], else sums_);
  // their total SSE.
  double Solve(std::size_t p, std::vector<LinearSolution>* out) {
    double total = 0;
    if (out != nullptr) out->clear();
    for (BandSums& s : sums_) {
      if (shared_) {
        const std::size_t b = static_cast<std::size_t>(&s - sums_.data());
        s.sws = shared_sums_[p].sws;
        s.swss = shared_sums_[p].swss;
        s.swsf = swsf_[p * panels() * kPanel + b];
      }
      const LinearSolution sol = SolveBand(s);
      total += sol.sse;
      if (out != nullptr) out->push_back(sol);
    }
    return total;
  }

  // Each band's products with the lobe shape s: 1ᵀV⁻¹s, sᵀV⁻¹f, sᵀV⁻¹s.
  void BandLobeSums(std::span<const double> spec) {
    for (std::size_t b = b0_; b < b1_; ++b) {
      BandSums& s = sums_[b - b0_];
      s.sws = Dot(spec, v_one_[b - b0_]);
      s.swsf = Dot(spec, v_f_[b - b0_]);
      s.swss = covariance_[b].Product(spec, spec);
    }
  }

  std::size_t panels() const { return (b1_ - b0_ + kPanel - 1) / kPanel; }

  // The same products for k shapes when every band has the same diagonal V (unweighted data):
  // 1ᵀV⁻¹s and sᵀV⁻¹s are then one value for all bands, taken once per shape, and every band's
  // sᵀV⁻¹f of all k shapes in one pass over the panels (PanelSums). Each band's sum still adds
  // the observations in their order from 0, so every value is BandLobeSums' to the bit.
  void SharedLobeSums(std::size_t k) {
    const std::size_t n = data_.size();
    std::array<const double*, kMaxShapes> x{};
    for (std::size_t p = 0; p < k; ++p) {
      const std::span<const double> spec(shapes_.data() + p * n, n);
      x[p] = spec.data();
      shared_sums_[p].sws = Dot(spec, v_one_[0]);
      shared_sums_[p].swss = covariance_[b0_].Product(spec, spec);
    }
    swsf_.resize(kMaxShapes * panels() * kPanel);
    std::array<double, kMaxShapes * kPanel> sum;
    for (std::size_t q = 0; q < panels(); ++q) {
      PanelSums(panels_.data() + q * kPanel * n, n, x.data(), k, sum.data());
      for (std::size_t p = 0; p < k; ++p) {
        std::copy_n(
            sum.begin() + static_cast<std::ptrdiff_t>(p * kPanel), kPanel,
            swsf_.begin() + static_cast<std::ptrdiff_t>(p * panels() * kPanel + q * kPanel));
      }
    }
  }

  const Observations& data_;
  const std::vector<BandCovariance>& covariance_;
  std::size_t b0_, b1_;
  const bool shared_;  // every band's V the same diagonal one (SharedDiagonal)
  std::vector<BandSums> sums_;
  std::vector<std::vector<double>> v_one_, v_f_;  // V⁻¹1 and V⁻¹f per band (shared_: V⁻¹1 once)
  std::vector<double> panels_;                    // shared_: V⁻¹f, kPanel bands side by side
  std::array<BandSums, kMaxShapes> shared_sums_;  // shared_: 1ᵀV⁻¹s and sᵀV⁻¹s per shape
  std::vector<double> swsf_;                      // shared_: sᵀV⁻¹f per shape and band
  std::vector<LobeGeometry> geometry_;
  std::vector<double> shapes_;  // the lobe shapes being tried, one per observation each
};

struct SearchResult {
  double alpha = 0, f0 = 0, sse = std::numeric_limits<double>::infinity();
  int evaluations = 0;
  bool converged = true;
};

// From each start, a Nelder-Mead search and a restart from its result (which guards against a
// simplex that collapsed early); the best result wins, the earlier start on a tie. The searches
// run side by side, their points evaluated together (Projection::EvaluateAll), each search
// taking the same steps as alone.
SearchResult Search(Projection& projection, const CookTorranceOptions& options,
                    const CallContext& ctx) {
  NelderMeadOptions nm;
  nm.max_evaluations = options.max_evaluations;
  nm.stop = [&ctx] { return ctx.cancelled() || ctx.expired(); };
  // A whole step per pass over the data when a pass is what costs (many bands); band by band,
  // the lobe shapes cost more than the sums and are not computed ahead.
  nm.speculate = projection.shared();
  const double step[2] = {0.7, 1.0};
  struct Run {
    NelderMeadSearch search;
    std::vector<NelderMeadResult> done;  // the search's, then the restart's
  };
  std::vector<Run> runs;
  for (double a0 : options.alpha_starts) {
    const double start[2] = {std::log(a0), Logit(options.f0_start)};
    runs.push_back({NelderMeadSearch(start, step, nm), {}});
  }
  std::vector<std::array<double, 2>> points;
  for (;;) {
    points.clear();
    for (const Run& r : runs) {
      for (const std::vector<double>& x : r.search.Pending()) {
        points.push_back({AlphaOf(x[0]), F0Of(x[1])});
      }
    }
    if (points.empty()) break;
    const std::vector<double> values = projection.EvaluateAll(points);
    std::size_t at = 0;
    for (Run& r : runs) {
      const std::size_t k = r.search.Pending().size();
      if (k == 0) continue;
      r.search.Tell({values.data() + at, k});
      at += k;
      if (!r.search.done()) continue;
      r.done.push_back(r.search.result());
      if (r.done.size() == 1) r.search = NelderMeadSearch(r.done.front().x, step, nm);
    }
  }
  SearchResult best;
  for (const Run& r : runs) {
    const NelderMeadResult& again = r.done.back();
    best.evaluations += r.done.front().evaluations + again.evaluations;
    best.converged = best.converged && again.converged;
    if (again.value < best.sse) {
      best.sse = again.value;
      best.alpha = AlphaOf(again.x[0]);
      best.f0 = F0Of(again.x[1]);
    }
  }
  return best;
}

// JᵀV⁻¹J of bands [b0, b1) over (kd, ks of each band, then α, F0) at the fit in `band`: kd and
// ks enter linearly (∂f/∂kd = 1/π, ∂f/∂ks = s); the lobe's ∂s/∂α and ∂s/∂F0 by central
// differences. Bands do not covary, so each band adds its own 4 × 4 block of products.
std::vector<double> CookTorranceNormalMatrix(const Observations& data,
                                             const std::vector<BandCovariance>& covariance,
                                             std::size_t b0, std::size_t b1,
                                             const std::vector<CookTorranceParams>& band) {
  const std::size_t nb = b1 - b0, n = 2 * nb + 2, count = data.size();
  const double alpha = band[b0].alpha, f0 = band[b0].f0;
  const double ha = 1e-4 * alpha, hf = 1e-3;
  std::vector<double> s(count), dsa(count), dsf(count);
  for (std::size_t i = 0; i < count; ++i) {
    const LobeGeometry g = LobeGeometryOf(data.direction(i));
    s[i] = CookTorranceSpecularAt(g, alpha, f0);
    dsa[i] =
        (CookTorranceSpecularAt(g, alpha + ha, f0) - CookTorranceSpecularAt(g, alpha - ha, f0)) /
        (2 * ha);
    dsf[i] =
        (CookTorranceSpecularAt(g, alpha, f0 + hf) - CookTorranceSpecularAt(g, alpha, f0 - hf)) /
        (2 * hf);
  }
  std::vector<double> m(n * n, 0.0);
  std::vector<std::vector<double>> columns(4, std::vector<double>(count));
  for (std::size_t b = b0; b < b1; ++b) {
    const double ks = band[b].ks;
    for (std::size_t i = 0; i < count; ++i) {
      columns[0][i] = 1.0 / kPi;
      columns[1][i] = s[i];
      columns[2][i] = ks * dsa[i];
      columns[3][i] = ks * dsf[i];
    }
    const std::vector<double> g = covariance[b].Gram(columns);
    const std::size_t at[4] = {2 * (b - b0), 2 * (b - b0) + 1, n - 2, n - 1};
    for (int p = 0; p < 4; ++p) {
      for (int q = 0; q < 4; ++q) m[at[p] * n + at[q]] += g[p * 4 + q];
    }
  }
  return m;
}

// The standard uncertainties of bands [b0, b1)'s parameters into fit.band_u. kd or ks at 0 is at
// its bound and not counted free; α and F0 are free when some band has a lobe (ks > 0) and they
// are inside their ranges.
// `group`: the statistics of these bands alone (for the unweighted scaling); its note goes to
// `note` when that is still empty.
void CookTorranceUncertainties(const Observations& data,
                               const std::vector<BandCovariance>& covariance, std::size_t b0,
                               std::size_t b1, FitStatistics group, CookTorranceFit& fit,
                               std::string& note) {
  const std::size_t nb = b1 - b0, n = 2 * nb + 2;
  std::vector<bool> free(n, false);
  bool lobe = false;
  for (std::size_t b = b0; b < b1; ++b) {
    free[2 * (b - b0)] = fit.band[b].kd > 0;
    free[2 * (b - b0) + 1] = fit.band[b].ks > 0;
    lobe = lobe || fit.band[b].ks > 0;
  }
  // α at its clamp and F0 at 0 or 1 (the logistic's ends) are at their bounds too.
  const double alpha = fit.band[b0].alpha, f0 = fit.band[b0].f0;
  free[n - 2] = lobe && alpha > kAlphaMin * (1 + 1e-9) && alpha < kAlphaMax * (1 - 1e-9);
  free[n - 1] = lobe && f0 > 1e-6 && f0 < 1 - 1e-6;
  const std::vector<double> u = ParameterUncertainties(
      CookTorranceNormalMatrix(data, covariance, b0, b1, fit.band), n, free, group);
  for (std::size_t b = b0; b < b1; ++b) {
    fit.band_u[b] = CookTorranceParams{u[2 * (b - b0)], u[2 * (b - b0) + 1], u[n - 2], u[n - 1]};
  }
  if (note.empty()) note = group.note;
}

// The fitted lobe s(i, band) at every observation, each direction's angles taken once: the same
// value as CookTorranceSpecular(data.direction(i), α, F0) of the band, so that kd/π + ks·s is
// CookTorranceBrdf's to the bit without its sin and cos for every band. Shared α and F0: one
// value per observation, computed here; per band: from the angles, when asked.
class FittedLobe {
 public:
  FittedLobe(const Observations& data, const std::vector<CookTorranceParams>& band, bool shared)
      : band_(band), shared_(shared) {
    geometry_.reserve(data.size());
    for (std::size_t i = 0; i < data.size(); ++i) {
      geometry_.push_back(LobeGeometryOf(data.direction(i)));
    }
    if (!shared_ || band.empty()) return;
    value_.reserve(data.size());
    for (const LobeGeometry& g : geometry_) {
      value_.push_back(CookTorranceSpecularAt(g, band.front().alpha, band.front().f0));
    }
  }

  double At(std::size_t i, std::size_t b) const {
    return shared_ ? value_[i] : CookTorranceSpecularAt(geometry_[i], band_[b].alpha, band_[b].f0);
  }

 private:
  const std::vector<CookTorranceParams>& band_;
  const bool shared_;
  std::vector<LobeGeometry> geometry_;
  std::vector<double> value_;  // shared_: per observation
};

}  // namespace

const char* ParameterSharingName(ParameterSharing s) {
  return s == ParameterSharing::kPerBand ? "per_band" : "shared";
}

Residuals ResidualsOf(const Observations& data, std::size_t band_begin, std::size_t band_end,
                      const std::function<double(std::size_t, std::size_t)>& model) {
  Residuals r;
  double srr = 0, sff = 0;
  for (std::size_t i = 0; i < data.size(); ++i) {
    for (std::size_t b = band_begin; b < band_end; ++b) {
      const double f = data.value(i, b);
      const double d = model(i, b) - f;
      srr += d * d;
      sff += f * f;
      r.max_abs = std::max(r.max_abs, std::abs(d));
      ++r.count;
    }
  }
  if (r.count > 0) r.rms = std::sqrt(srr / static_cast<double>(r.count));
  r.relative_rms = sff > 0 ? std::sqrt(srr / sff) : (srr > 0 ? 1.0 : 0.0);
  return r;
}

Result<LambertFit> FitLambert(const Observations& data) {
  if (data.size() == 0) {
    return FailedPrecondition("Lambert fit: no observations (no usable BRDF readings)");
  }
  const std::vector<ScaleSource> scales = ScaleSourcesOf(data);
  Result<std::vector<BandCovariance>> made = CovariancesOf(data, scales);
  if (!made.ok()) return made.status().WithContext("Lambert fit");
  const std::vector<BandCovariance>& covariance = *made;
  LambertFit fit;
  fit.grid = data.grid();
  const std::size_t nb = data.bands(), n = data.size();
  // ρ/π = 1ᵀV⁻¹f / 1ᵀV⁻¹1 per band (generalised least squares of a constant), u(ρ) = π/√1ᵀV⁻¹1.
  const std::vector<double> one(n, 1.0);
  std::vector<double> sw(nb);
  fit.albedo.resize(nb);
  for (std::size_t b = 0; b < nb; ++b) {
    sw[b] = covariance[b].Product(one, one);
    fit.albedo[b] = covariance[b].Product(one, BandValues(data, b)) / sw[b] * kPi;
  }
  auto model = [&](std::size_t, std::size_t b) { return LambertBrdf(fit.albedo[b]); };
  for (std::size_t b = 0; b < nb; ++b) {
    fit.band_residuals.push_back(ResidualsOf(data, b, b + 1, model));
    // Unweighted, scaled by the band's residual variance Σ r² / (n − 1).
    const double r2 = fit.band_residuals[b].rms * fit.band_residuals[b].rms;
    const double scale = data.weighted() ? 1.0
                         : n > 1         ? r2 * static_cast<double>(n) / static_cast<double>(n - 1)
                                         : std::numeric_limits<double>::quiet_NaN();
    fit.albedo_u.push_back(
        WithScales(kPi * std::sqrt(scale / sw[b]), fit.albedo[b], ScaleVariance(scales, b)));
  }
  fit.overall = ResidualsOf(data, 0, nb, model);
  fit.statistics = StatisticsOf(data, WeightedSumOfSquares(data, covariance, model), n * nb, nb);
  fit.statistics.scale_terms = scales.size();
  return fit;
}

double WeightedSumOfSquares(const Observations& data, const std::vector<BandCovariance>& covariance,
                            const std::function<double(std::size_t, std::size_t)>& model) {
  double sum = 0;
  std::vector<double> r(data.size());
  for (std::size_t b = 0; b < data.bands(); ++b) {
    for (std::size_t i = 0; i < data.size(); ++i) r[i] = model(i, b) - data.value(i, b);
    sum += covariance[b].Product(r, r);
  }
  return sum;
}

Result<CookTorranceFit> FitCookTorrance(const Observations& data,
                                        const CookTorranceOptions& options,
                                        const CallContext& ctx) {
  if (data.size() < 3) {
    return FailedPrecondition("Cook-Torrance fit: " + std::to_string(data.size()) +
                              " observations; at least 3 are needed (kd, ks and the lobe's shape)");
  }
  if (options.alpha_starts.empty()) {
    return InvalidArgument("Cook-Torrance fit: no starting roughness (alpha_starts is empty)");
  }
  for (double a : options.alpha_starts) {
    if (!(a > 0) || !std::isfinite(a)) {
      return InvalidArgument("Cook-Torrance fit: starting roughness " + std::to_string(a) +
                             " is not a positive number");
    }
  }
  if (!(options.f0_start > 0 && options.f0_start < 1)) {
    return InvalidArgument("Cook-Torrance fit: f0_start must lie strictly between 0 and 1");
  }
  const std::vector<ScaleSource> scales = ScaleSourcesOf(data);
  Result<std::vector<BandCovariance>> made = CovariancesOf(data, scales);
  if (!made.ok()) return made.status().WithContext("Cook-Torrance fit");
  const std::vector<BandCovariance>& covariance = *made;
  const std::size_t nb = data.bands();
  CookTorranceFit fit;
  fit.grid = data.grid();
  fit.sharing = options.sharing;
  fit.band.resize(nb);
  fit.band_u.resize(nb);
  fit.converged = true;

  auto record = [&](std::size_t b0, std::size_t b1, const SearchResult& s,
                    const std::vector<LinearSolution>& sol) {
    for (std::size_t b = b0; b < b1; ++b) {
      fit.band[b] = CookTorranceParams{sol[b - b0].kd, sol[b - b0].ks, s.alpha, s.f0};
    }
    fit.evaluations += s.evaluations;
    fit.converged = fit.converged && s.converged;
  };
  const std::size_t groups = options.sharing == ParameterSharing::kPerBand ? nb : 1;
  std::string note;
  for (std::size_t g = 0; g < groups; ++g) {
    const std::size_t b0 = groups == 1 ? 0 : g, b1 = groups == 1 ? nb : g + 1;
    Projection projection(data, covariance, b0, b1);
    const SearchResult s = Search(projection, options, ctx);
    if (ctx.cancelled()) return Cancelled("Cook-Torrance fit cancelled: " + ctx.cancel().reason());
    if (ctx.expired()) {
      return Timeout("Cook-Torrance fit ran past its deadline after " + std::to_string(g) + " of " +
                     std::to_string(groups) + " searches; allow more time");
    }
    std::vector<LinearSolution> sol;
    const double sse = projection.Evaluate(s.alpha, s.f0, &sol);
    record(b0, b1, s, sol);
    const std::size_t group_parameters = 2 * (b1 - b0) + 2;
    CookTorranceUncertainties(data, covariance, b0, b1,
                              StatisticsOf(data, sse, data.size() * (b1 - b0), group_parameters),
                              fit, note);
    if (options.progress)
      options.progress(static_cast<double>(g + 1) / static_cast<double>(groups));
  }

  const FittedLobe lobe(data, fit.band, groups == 1);
  auto model = [&](std::size_t i, std::size_t b) {
    return fit.band[b].kd / kPi + fit.band[b].ks * lobe.At(i, b);
  };
  for (std::size_t b = 0; b < nb; ++b) {
    fit.band_residuals.push_back(ResidualsOf(data, b, b + 1, model));
    // A scale of the whole band moves kd and ks together (not α, F0).
    const double f2 = ScaleVariance(scales, b);
    fit.band_u[b].kd = WithScales(fit.band_u[b].kd, fit.band[b].kd, f2);
    fit.band_u[b].ks = WithScales(fit.band_u[b].ks, fit.band[b].ks, f2);
  }
  fit.overall = ResidualsOf(data, 0, nb, model);
  const std::size_t parameters = groups == 1 ? 2 * nb + 2 : 4 * nb;
  fit.statistics = StatisticsOf(data, WeightedSumOfSquares(data, covariance, model),
                                data.size() * nb, parameters);
  fit.statistics.note = note;
  fit.statistics.scale_terms = scales.size();
  return fit;
}

}  // namespace brdf::fit
