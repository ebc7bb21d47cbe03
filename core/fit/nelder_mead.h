// A small Nelder-Mead simplex minimiser (no derivatives, no external dependency), for the few
// non-linear parameters of a reflection model. Unconstrained: map bounded parameters through a
// transform (log, logistic) in the objective.
#pragma once

#include <functional>
#include <span>
#include <vector>

namespace brdf::fit {

struct NelderMeadOptions {
  int max_evaluations = 2000;
  // Stops when the simplex's values differ by at most f_tolerance · (|f_best| + 1e-30) and its
  // vertices by at most x_tolerance in every coordinate.
  double f_tolerance = 1e-12;
  double x_tolerance = 1e-9;
  // Optional: checked every iteration; true stops the search (cancellation).
  std::function<bool()> stop;
};

struct NelderMeadResult {
  std::vector<double> x;  // the best point found
  double value = 0;       // the objective there
  int evaluations = 0;
  bool converged = false;  // the tolerances were met (not the evaluation cap, not stopped)
};

// Minimises `f` from `start`, with an initial simplex of start + step[j]·e_j. A non-finite value
// counts as +∞ (the simplex moves away from it).
NelderMeadResult MinimizeNelderMead(const std::function<double(std::span<const double>)>& f,
                                    std::span<const double> start, std::span<const double> step,
                                    const NelderMeadOptions& options = {});

}  // namespace brdf::fit
