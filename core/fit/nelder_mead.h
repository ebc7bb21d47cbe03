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
  // NelderMeadSearch only: Pending() asks for the reflection together with the step's other
  // candidates (expansion, outside and inside contraction), so that one pass evaluates the whole
  // step; the step uses the same values as without, and counts only those as evaluations.
  bool speculate = false;
};

struct NelderMeadResult {
  std::vector<double> x;  // the best point found
  double value = 0;       // the objective there
  int evaluations = 0;
  bool converged = false;  // the tolerances were met (not the evaluation cap, not stopped)
};

// The same search asked for its points and told their values, so that a caller can evaluate the
// points of several searches together (one pass over the data for all of them): Pending() are
// the points the search needs next (all n + 1 vertices at first, then one, or n when it shrinks),
// Tell() their values in that order. The same steps, points and result as MinimizeNelderMead.
class NelderMeadSearch {
 public:
  NelderMeadSearch(std::span<const double> start, std::span<const double> step,
                   NelderMeadOptions options = {});

  bool done() const { return phase_ == Phase::kDone; }
  const std::vector<std::vector<double>>& Pending() const { return pending_; }
  void Tell(std::span<const double> values);
  const NelderMeadResult& result() const { return result_; }  // once done()

 private:
  enum class Phase { kStart, kReflect, kExpand, kContract, kShrink, kDone };
  void Advance();  // ranks, stops or reflects the worst vertex
  // The reflection's value (and, speculated, the expansion's and the contractions'): false
  // when the step needs more points.
  bool Reflected(std::span<const double> values);
  void Expanded(const std::vector<double>& expanded, double fe);
  bool Contracted(const std::vector<double>& contracted, double fc);  // false: shrinks
  void ReplaceWorst(const std::vector<double>& p, double v);
  void Finish();

  NelderMeadOptions options_;
  std::vector<std::vector<double>> pts_;
  std::vector<double> vals_;
  std::vector<std::size_t> order_;
  std::vector<double> centroid_, reflected_;
  double fr_ = 0;
  bool outside_ = false;
  Phase phase_ = Phase::kStart;
  std::vector<std::vector<double>> pending_;
  NelderMeadResult result_;
};

// Minimises `f` from `start`, with an initial simplex of start + step[j]·e_j. A non-finite value
// counts as +∞ (the simplex moves away from it).
NelderMeadResult MinimizeNelderMead(const std::function<double(std::span<const double>)>& f,
                                    std::span<const double> start, std::span<const double> step,
                                    const NelderMeadOptions& options = {});

}  // namespace brdf::fit
