#include "core/fit/nelder_mead.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <numeric>
#include <utility>

namespace brdf::fit {
namespace {

// A non-finite value counts as +∞.
double Finite(double v) {
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
  const std::vector<std::vector<double>>& pts;
  const std::vector<double>& vals;
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

}  // namespace

NelderMeadSearch::NelderMeadSearch(std::span<const double> start, std::span<const double> step,
                                   NelderMeadOptions options)
    : options_(std::move(options)) {
  const std::size_t n = start.size();
  pts_.assign(n + 1, std::vector<double>(start.begin(), start.end()));
  for (std::size_t j = 0; j < n; ++j) pts_[j + 1][j] += step[j];
  vals_.resize(n + 1);
  order_.resize(n + 1);
  pending_ = pts_;
}

void NelderMeadSearch::ReplaceWorst(const std::vector<double>& p, double v) {
  pts_[order_.back()] = p;
  vals_[order_.back()] = v;
}

void NelderMeadSearch::Finish() {
  const std::size_t best =
      static_cast<std::size_t>(std::min_element(vals_.begin(), vals_.end()) - vals_.begin());
  result_.x = pts_[best];
  result_.value = vals_[best];
  pending_.clear();
  phase_ = Phase::kDone;
}

// One step from the ranked simplex, with the standard coefficients: reflection 1, expansion 2,
// contraction ½, shrink ½ towards the best. Advance reflects; Tell takes each value in turn.
void NelderMeadSearch::Advance() {
  if (result_.evaluations >= options_.max_evaluations || (options_.stop && options_.stop())) {
    Finish();
    return;
  }
  const Simplex s{pts_, vals_};
  Rank(s, order_);
  if (Converged(s, order_.front(), order_.back(), options_)) {
    result_.converged = true;
    Finish();
    return;
  }
  centroid_ = Centroid(s, order_.back());
  reflected_ = Along(centroid_, pts_[order_.back()], -1.0);
  pending_.assign(1, reflected_);
  if (options_.speculate) {
    for (const double t : {-2.0, -0.5, 0.5})
      pending_.push_back(Along(centroid_, pts_[order_.back()], t));
  }
  phase_ = Phase::kReflect;
}

void NelderMeadSearch::Tell(std::span<const double> values) {
  const std::size_t n = order_.size() - 1;
  switch (phase_) {
    case Phase::kStart:
      result_.evaluations += static_cast<int>(n + 1);
      for (std::size_t i = 0; i <= n; ++i) vals_[i] = Finite(values[i]);
      break;
    case Phase::kReflect:
      if (!Reflected(values)) return;
      break;
    case Phase::kExpand:
      ++result_.evaluations;
      Expanded(pending_[0], Finite(values[0]));
      break;
    case Phase::kContract:
      ++result_.evaluations;
      if (!Contracted(pending_[0], Finite(values[0]))) return;
      break;
    case Phase::kShrink:
      result_.evaluations += static_cast<int>(n);
      for (std::size_t i = 0, k = 0; i <= n; ++i) {
        if (i == order_.front()) continue;
        pts_[i] = pending_[k];
        vals_[i] = Finite(values[k++]);
      }
      break;
    case Phase::kDone:
      return;
  }
  Advance();
}

bool NelderMeadSearch::Reflected(std::span<const double> values) {
  ++result_.evaluations;
  const std::size_t n = order_.size() - 1, worst = order_.back();
  const bool all = values.size() > 1;  // speculated: the other candidates' values too
  fr_ = Finite(values[0]);
  if (fr_ < vals_[order_.front()]) {
    if (!all) {
      pending_.assign(1, Along(centroid_, pts_[worst], -2.0));
      phase_ = Phase::kExpand;
      return false;
    }
    ++result_.evaluations;
    Expanded(pending_[1], Finite(values[1]));
    return true;
  }
  if (fr_ < vals_[order_[n - 1]]) {
    ReplaceWorst(reflected_, fr_);
    return true;
  }
  // Contract: outside when the reflection improved on the worst, inside otherwise.
  outside_ = fr_ < vals_[worst];
  if (!all) {
    pending_.assign(1, Along(centroid_, pts_[worst], outside_ ? -0.5 : 0.5));
    phase_ = Phase::kContract;
    return false;
  }
  ++result_.evaluations;
  const std::size_t c = outside_ ? 2 : 3;
  return Contracted(pending_[c], Finite(values[c]));
}

void NelderMeadSearch::Expanded(const std::vector<double>& expanded, double fe) {
  if (fe < fr_) {
    ReplaceWorst(expanded, fe);
  } else {
    ReplaceWorst(reflected_, fr_);
  }
}

bool NelderMeadSearch::Contracted(const std::vector<double>& contracted, double fc) {
  if (fc < (outside_ ? fr_ : vals_[order_.back()])) {
    ReplaceWorst(contracted, fc);
    return true;
  }
  std::vector<std::vector<double>> shrunk;  // `contracted` may be one of pending_
  for (std::size_t i = 0; i < pts_.size(); ++i) {
    if (i != order_.front()) shrunk.push_back(Along(pts_[order_.front()], pts_[i], 0.5));
  }
  pending_ = std::move(shrunk);
  phase_ = Phase::kShrink;
  return false;
}

NelderMeadResult MinimizeNelderMead(const std::function<double(std::span<const double>)>& f,
                                    std::span<const double> start, std::span<const double> step,
                                    const NelderMeadOptions& options) {
  NelderMeadSearch search(start, step, options);
  std::vector<double> values;
  while (!search.done()) {
    values.clear();
    for (const std::vector<double>& p : search.Pending()) values.push_back(f(p));
    search.Tell(values);
  }
  return search.result();
}

}  // namespace brdf::fit
