#include "core/fit/nelder_mead.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <numeric>

namespace brdf::fit {

NelderMeadResult MinimizeNelderMead(const std::function<double(std::span<const double>)>& f,
                                    std::span<const double> start, std::span<const double> step,
                                    const NelderMeadOptions& options) {
  const std::size_t n = start.size();
  NelderMeadResult result;
  auto eval = [&](const std::vector<double>& x) {
    ++result.evaluations;
    const double v = f(x);
    return std::isfinite(v) ? v : std::numeric_limits<double>::infinity();
  };

  // Standard coefficients: reflection 1, expansion 2, contraction ½, shrink ½.
  std::vector<std::vector<double>> pts(n + 1, std::vector<double>(start.begin(), start.end()));
  for (std::size_t j = 0; j < n; ++j) pts[j + 1][j] += step[j];
  std::vector<double> vals(n + 1);
  for (std::size_t i = 0; i <= n; ++i) vals[i] = eval(pts[i]);
  std::vector<std::size_t> order(n + 1);

  auto point = [&](const std::vector<double>& c, const std::vector<double>& w, double t) {
    std::vector<double> p(n);
    for (std::size_t j = 0; j < n; ++j) p[j] = c[j] + t * (w[j] - c[j]);
    return p;
  };

  while (result.evaluations < options.max_evaluations) {
    if (options.stop && options.stop()) break;
    std::iota(order.begin(), order.end(), std::size_t{0});
    std::sort(order.begin(), order.end(), [&](std::size_t a, std::size_t b) {
      return vals[a] < vals[b] || (vals[a] == vals[b] && a < b);
    });
    const std::size_t best = order.front(), worst = order.back(), second = order[n - 1];

    double x_spread = 0;
    for (std::size_t i = 0; i <= n; ++i) {
      for (std::size_t j = 0; j < n; ++j) {
        x_spread = std::max(x_spread, std::abs(pts[i][j] - pts[best][j]));
      }
    }
    const double f_spread = vals[worst] - vals[best];
    if (std::isfinite(f_spread) &&
        f_spread <= options.f_tolerance * (std::abs(vals[best]) + 1e-30) &&
        x_spread <= options.x_tolerance) {
      result.converged = true;
      break;
    }

    std::vector<double> centroid(n, 0.0);
    for (std::size_t i = 0; i <= n; ++i) {
      if (i == worst) continue;
      for (std::size_t j = 0; j < n; ++j) centroid[j] += pts[i][j] / static_cast<double>(n);
    }
    const std::vector<double> reflected = point(centroid, pts[worst], -1.0);
    const double fr = eval(reflected);
    if (fr < vals[best]) {
      const std::vector<double> expanded = point(centroid, pts[worst], -2.0);
      const double fe = eval(expanded);
      if (fe < fr) {
        pts[worst] = expanded;
        vals[worst] = fe;
      } else {
        pts[worst] = reflected;
        vals[worst] = fr;
      }
      continue;
    }
    if (fr < vals[second]) {
      pts[worst] = reflected;
      vals[worst] = fr;
      continue;
    }
    // Contract: outside when the reflection improved on the worst, inside otherwise.
    const bool outside = fr < vals[worst];
    const std::vector<double> contracted = point(centroid, pts[worst], outside ? -0.5 : 0.5);
    const double fc = eval(contracted);
    if (fc < (outside ? fr : vals[worst])) {
      pts[worst] = contracted;
      vals[worst] = fc;
      continue;
    }
    for (std::size_t i = 0; i <= n; ++i) {
      if (i == best) continue;
      pts[i] = point(pts[best], pts[i], 0.5);
      vals[i] = eval(pts[i]);
    }
  }
  const std::size_t best =
      static_cast<std::size_t>(std::min_element(vals.begin(), vals.end()) - vals.begin());
  result.x = pts[best];
  result.value = vals[best];
  return result;
}

}  // namespace brdf::fit
