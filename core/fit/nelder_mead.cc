#include "core/fit/nelder_mead.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <numeric>

namespace brdf::fit {
namespace {

// f at x, counted in result.evaluations; a non-finite value counts as +∞.
double Evaluate(const std::function<double(std::span<const double>)>& f,
                const std::vector<double>& x, NelderMeadResult& result) {
  ++result.evaluations;
  const double v = f(x);
  return std::isfinite(v) ? v : std::numeric_limits<double>::infinity();
}

// c + t · (w − c).
std::vector<double> Along(const std::vector<double>& c, const std::vector<double>& w, double t) {
  std::vector<double> p(c.size());
  for (std::size_t j = 0; j < c.size(); ++j) p[j] = c[j] + t * (w[j] - c[j]);
  return p;
}

// The n + 1 vertices and their values.
struct Simplex {
  std::vector<std::vector<double>> pts;
  std::vector<double> vals;
};

// The vertices from best to worst (ties: the lower index first) into `order`.
void Rank(const Simplex& s, std::vector<std::size_t>& order) {
  std::iota(order.begin(), order.end(), std::size_t{0});
  std::sort(order.begin(), order.end(), [&](std::size_t a, std::size_t b) {
    return s.vals[a] < s.vals[b] || (s.vals[a] == s.vals[b] && a < b);
  });
}

bool Converged(const Simplex& s, std::size_t best, std::size_t worst,
               const NelderMeadOptions& options) {
  double x_spread = 0;
  for (const std::vector<double>& p : s.pts) {
    for (std::size_t j = 0; j < p.size(); ++j) {
      x_spread = std::max(x_spread, std::abs(p[j] - s.pts[best][j]));
    }
  }
  const double f_spread = s.vals[worst] - s.vals[best];
  return std::isfinite(f_spread) &&
         f_spread <= options.f_tolerance * (std::abs(s.vals[best]) + 1e-30) &&
         x_spread <= options.x_tolerance;
}

// The centroid of every vertex but the worst.
std::vector<double> Centroid(const Simplex& s, std::size_t worst) {
  const std::size_t n = s.pts.size() - 1;
  std::vector<double> centroid(n, 0.0);
  for (std::size_t i = 0; i <= n; ++i) {
    if (i == worst) continue;
    for (std::size_t j = 0; j < n; ++j) centroid[j] += s.pts[i][j] / static_cast<double>(n);
  }
  return centroid;
}

// One step from the ranked simplex, with the standard coefficients: reflection 1, expansion 2,
// contraction ½, shrink ½ towards the best.
template <typename Eval>
void Step(Simplex& s, const std::vector<std::size_t>& order, Eval&& eval) {
  const std::size_t n = order.size() - 1;
  const std::size_t best = order.front(), worst = order.back(), second = order[n - 1];
  const std::vector<double> centroid = Centroid(s, worst);
  auto replace_worst = [&](const std::vector<double>& p, double v) {
    s.pts[worst] = p;
    s.vals[worst] = v;
  };
  const std::vector<double> reflected = Along(centroid, s.pts[worst], -1.0);
  const double fr = eval(reflected);
  if (fr < s.vals[best]) {
    const std::vector<double> expanded = Along(centroid, s.pts[worst], -2.0);
    const double fe = eval(expanded);
    if (fe < fr) {
      replace_worst(expanded, fe);
    } else {
      replace_worst(reflected, fr);
    }
    return;
  }
  if (fr < s.vals[second]) {
    replace_worst(reflected, fr);
    return;
  }
  // Contract: outside when the reflection improved on the worst, inside otherwise.
  const bool outside = fr < s.vals[worst];
  const std::vector<double> contracted = Along(centroid, s.pts[worst], outside ? -0.5 : 0.5);
  const double fc = eval(contracted);
  if (fc < (outside ? fr : s.vals[worst])) {
    replace_worst(contracted, fc);
    return;
  }
  for (std::size_t i = 0; i <= n; ++i) {
    if (i == best) continue;
    s.pts[i] = Along(s.pts[best], s.pts[i], 0.5);
    s.vals[i] = eval(s.pts[i]);
  }
}

}  // namespace

NelderMeadResult MinimizeNelderMead(const std::function<double(std::span<const double>)>& f,
                                    std::span<const double> start, std::span<const double> step,
                                    const NelderMeadOptions& options) {
  const std::size_t n = start.size();
  NelderMeadResult result;
  auto eval = [&](const std::vector<double>& x) { return Evaluate(f, x, result); };

  Simplex s;
  s.pts.assign(n + 1, std::vector<double>(start.begin(), start.end()));
  for (std::size_t j = 0; j < n; ++j) s.pts[j + 1][j] += step[j];
  s.vals.resize(n + 1);
  for (std::size_t i = 0; i <= n; ++i) s.vals[i] = eval(s.pts[i]);
  std::vector<std::size_t> order(n + 1);
  while (result.evaluations < options.max_evaluations) {
    if (options.stop && options.stop()) break;
    Rank(s, order);
    if (Converged(s, order.front(), order.back(), options)) {
      result.converged = true;
      break;
    }
    Step(s, order, eval);
  }
  const std::size_t best =
      static_cast<std::size_t>(std::min_element(s.vals.begin(), s.vals.end()) - s.vals.begin());
  result.x = s.pts[best];
  result.value = s.vals[best];
  return result;
}

}  // namespace brdf::fit
