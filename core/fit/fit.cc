#include "core/fit/fit.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <numbers>
#include <string>

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

// Per-band sums for the linear part f ≈ kd·a + ks·b with a = 1/π.
struct BandSums {
  double sff = 0, sf = 0;
};

// The best non-negative (kd, ks) for one band and its sum of squared residuals, from the sums.
struct LinearSolution {
  double kd = 0, ks = 0, sse = 0;
};

LinearSolution SolveBand(double n, double sb, double sbb, const BandSums& s, double sbf) {
  const double a = 1.0 / kPi;
  const double saa = n * a * a, sab = a * sb, saf = a * s.sf;
  auto sse = [&](double kd, double ks) {
    return s.sff - 2 * (kd * saf + ks * sbf) + kd * kd * saa + 2 * kd * ks * sab + ks * ks * sbb;
  };
  LinearSolution best{0, 0, s.sff};
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

// The variable-projection objective over bands [b0, b1): evaluates the lobe shape for (α, F0)
// at every observation and solves each band's (kd, ks).
class Projection {
 public:
  Projection(const Observations& data, std::size_t b0, std::size_t b1)
      : data_(data), b0_(b0), b1_(b1), sums_(b1 - b0), spec_(data.size()), sbf_(b1 - b0) {
    geometry_.reserve(data.size());
    for (std::size_t i = 0; i < data.size(); ++i) {
      geometry_.push_back(LobeGeometryOf(data.direction(i)));
      for (std::size_t b = b0; b < b1; ++b) {
        const double f = data.value(i, b);
        sums_[b - b0].sff += f * f;
        sums_[b - b0].sf += f;
      }
    }
  }

  // Solves for (α, F0) and returns the total SSE; fills `out` (b1 − b0 solutions) when given.
  double Evaluate(double alpha, double f0, std::vector<LinearSolution>* out) {
    double sb = 0, sbb = 0;
    for (std::size_t i = 0; i < data_.size(); ++i) {
      const double s = CookTorranceSpecularAt(geometry_[i], alpha, f0);
      spec_[i] = s;
      sb += s;
      sbb += s * s;
    }
    std::fill(sbf_.begin(), sbf_.end(), 0.0);
    for (std::size_t i = 0; i < data_.size(); ++i) {
      const double s = spec_[i];
      const std::span<const double> f = data_.spectrum(i);
      for (std::size_t b = b0_; b < b1_; ++b) sbf_[b - b0_] += s * f[b];
    }
    double total = 0;
    if (out != nullptr) out->clear();
    for (std::size_t b = b0_; b < b1_; ++b) {
      const LinearSolution sol =
          SolveBand(static_cast<double>(data_.size()), sb, sbb, sums_[b - b0_], sbf_[b - b0_]);
      total += sol.sse;
      if (out != nullptr) out->push_back(sol);
    }
    return total;
  }

 private:
  const Observations& data_;
  std::size_t b0_, b1_;
  std::vector<BandSums> sums_;
  std::vector<LobeGeometry> geometry_;
  std::vector<double> spec_;
  std::vector<double> sbf_;
};

struct SearchResult {
  double alpha = 0, f0 = 0, sse = std::numeric_limits<double>::infinity();
  int evaluations = 0;
  bool converged = true;
};

SearchResult Search(Projection& projection, const CookTorranceOptions& options,
                    const CallContext& ctx) {
  SearchResult best;
  best.converged = false;
  NelderMeadOptions nm;
  nm.max_evaluations = options.max_evaluations;
  nm.stop = [&ctx] { return ctx.cancelled() || ctx.expired(); };
  auto objective = [&](std::span<const double> x) {
    return projection.Evaluate(AlphaOf(x[0]), F0Of(x[1]), nullptr);
  };
  const double step[2] = {0.7, 1.0};
  bool all_converged = true;
  for (double a0 : options.alpha_starts) {
    const double start[2] = {std::log(a0), Logit(options.f0_start)};
    NelderMeadResult r = MinimizeNelderMead(objective, start, step, nm);
    // A restart from the result guards against a simplex that collapsed early.
    NelderMeadResult again = MinimizeNelderMead(objective, r.x, step, nm);
    best.evaluations += r.evaluations + again.evaluations;
    all_converged = all_converged && again.converged;
    if (again.value < best.sse) {
      best.sse = again.value;
      best.alpha = AlphaOf(again.x[0]);
      best.f0 = F0Of(again.x[1]);
    }
    if (ctx.cancelled() || ctx.expired()) break;
  }
  best.converged = all_converged;
  return best;
}

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
  LambertFit fit;
  fit.grid = data.grid();
  const std::size_t nb = data.bands();
  fit.albedo.assign(nb, 0.0);
  for (std::size_t i = 0; i < data.size(); ++i) {
    for (std::size_t b = 0; b < nb; ++b) fit.albedo[b] += data.value(i, b);
  }
  for (double& a : fit.albedo) a = a / static_cast<double>(data.size()) * kPi;
  auto model = [&](std::size_t, std::size_t b) { return LambertBrdf(fit.albedo[b]); };
  for (std::size_t b = 0; b < nb; ++b)
    fit.band_residuals.push_back(ResidualsOf(data, b, b + 1, model));
  fit.overall = ResidualsOf(data, 0, nb, model);
  return fit;
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
  const std::size_t nb = data.bands();
  CookTorranceFit fit;
  fit.grid = data.grid();
  fit.sharing = options.sharing;
  fit.band.resize(nb);
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
  for (std::size_t g = 0; g < groups; ++g) {
    const std::size_t b0 = groups == 1 ? 0 : g, b1 = groups == 1 ? nb : g + 1;
    Projection projection(data, b0, b1);
    const SearchResult s = Search(projection, options, ctx);
    if (ctx.cancelled()) return Cancelled("Cook-Torrance fit cancelled: " + ctx.cancel().reason());
    if (ctx.expired()) {
      return Timeout("Cook-Torrance fit ran past its deadline after " + std::to_string(g) + " of " +
                     std::to_string(groups) + " searches; allow more time");
    }
    std::vector<LinearSolution> sol;
    projection.Evaluate(s.alpha, s.f0, &sol);
    record(b0, b1, s, sol);
    if (options.progress)
      options.progress(static_cast<double>(g + 1) / static_cast<double>(groups));
  }

  auto model = [&](std::size_t i, std::size_t b) {
    return CookTorranceBrdf(data.direction(i), fit.band[b]);
  };
  for (std::size_t b = 0; b < nb; ++b)
    fit.band_residuals.push_back(ResidualsOf(data, b, b + 1, model));
  fit.overall = ResidualsOf(data, 0, nb, model);
  return fit;
}

}  // namespace brdf::fit
