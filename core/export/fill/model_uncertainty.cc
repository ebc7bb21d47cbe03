#include "core/export/fill/model_uncertainty.h"

#include <algorithm>
#include <array>
#include <atomic>
#include <cmath>
#include <cstdint>
#include <limits>
#include <numbers>
#include <utility>

#include "core/export/fill/session_interpolant.h"
#include "core/fit/models.h"
#include "core/fit/observations.h"

namespace brdf::exports {
namespace {

constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();
constexpr double kInfinity = std::numeric_limits<double>::infinity();
constexpr double kRadian = std::numbers::pi / 180.0;

IsoDirection At(const interp::SampleSet& samples, std::size_t i) {
  const std::span<const double> c = samples.coords(i);
  return {c[0], c[1], c[2]};
}

// The model's value minus the reading's, per band of the reading (0 past the model's bands).
std::vector<double> ModelMinusReading(const fit::CookTorranceFit& model, const IsoDirection& at,
                                      std::span<const double> f) {
  std::vector<double> d(f.size(), 0.0);
  fit::CookTorranceSpectrumAt(fit::LobeGeometryOf(at), model.band, d);
  for (std::size_t b = 0; b < f.size() && b < model.band.size(); ++b) d[b] -= f[b];
  return d;
}

// ρ per band: the RMS of `residuals` over the readings `near`.
void LocalScale(const std::vector<std::vector<double>>& residuals,
                std::span<const std::size_t> near, std::span<double> rho) {
  std::fill(rho.begin(), rho.end(), 0.0);
  for (const std::size_t i : near) {
    // The bands both have, in a loop the compiler vectorises (the same sums band by band).
    const std::size_t bands = std::min(rho.size(), residuals[i].size());
    const double* r = residuals[i].data();
    double* to = rho.data();
    for (std::size_t b = 0; b < bands; ++b) to[b] += r[b] * r[b];
  }
  const double n = static_cast<double>(std::max<std::size_t>(1, near.size()));
  for (double& r : rho) r = std::sqrt(r / n);
}

// The readings of `samples` outside `held` (a fold), as a set of their own, and their positions.
std::shared_ptr<interp::SampleSet> Rest(const interp::SampleSet& samples,
                                        std::span<const std::size_t> held,
                                        std::vector<std::size_t>* rest_to_all) {
  std::vector<bool> is_held(samples.size(), false);
  for (const std::size_t j : held) is_held[j] = true;
  auto rest = std::make_shared<interp::SampleSet>(samples.dims(), samples.bands());
  for (std::size_t i = 0; i < samples.size(); ++i) {
    if (is_held[i] || !rest->Add(samples.id(i), samples.coords(i), samples.spectrum(i)).ok()) {
      continue;
    }
    rest_to_all->push_back(i);
  }
  return rest;
}

// The model fitted to `rest` as FitSampleModel fits a session's (the same subsample rule); an
// error when the fit fails.
Result<fit::CookTorranceFit> FitRest(const interp::SampleSet& rest, const WavelengthGrid& grid,
                                     const CallContext& ctx) {
  fit::Observations data(grid);
  for (const std::size_t i : ModelFitSamples(rest.size())) {
    if (Status st = data.Add(At(rest, i), rest.spectrum(i)); !st.ok()) return st;
  }
  return fit::FitCookTorrance(data, {}, ctx);
}

// One fold's points: the model fitted without `held`, each held reading predicted.
void PredictModelFold(const interp::SampleSet& samples, std::span<const std::size_t> held,
                      const WavelengthGrid& grid, const CallContext& ctx,
                      std::vector<uncertainty::HeldOutPoint>* out) {
  std::vector<std::size_t> rest_to_all;
  const std::shared_ptr<interp::SampleSet> rest = Rest(samples, held, &rest_to_all);
  if (rest->size() < kModelNeighbours) return;
  Result<fit::CookTorranceFit> model = FitRest(*rest, grid, ctx);
  if (!model.ok()) return;
  const std::vector<std::vector<double>> residuals = ModelResiduals(*model, *rest);
  const ReadingNeighbours neighbours(*rest);
  std::vector<std::size_t> near;
  std::vector<double> distance;
  for (const std::size_t j : held) {
    const IsoDirection at = At(samples, j);
    const std::span<const double> f = samples.spectrum(j);
    uncertainty::HeldOutPoint p;
    p.residual = ModelMinusReading(*model, at, f);
    neighbours.Nearest(at, kModelNeighbours, &near, &distance);
    p.spread.resize(f.size());
    LocalScale(residuals, near, p.spread);
    p.cell_size = distance.empty() ? 0.0 : distance.front();
    out->push_back(std::move(p));
  }
}

}  // namespace

namespace {

// ReadingDistance's formula from the cosines and sines of the two θo, computed once per direction
// for the many distances it takes part in: the same operations in the same order, so the same
// value, bit for bit.
double DistanceFrom(const IsoDirection& a, double cos_a, double sin_a, const IsoDirection& b,
                    double cos_b, double sin_b) {
  const double cos_gamma = cos_a * cos_b + sin_a * sin_b * std::cos((a.phi - b.phi) * kRadian);
  const double gamma = std::acos(std::clamp(cos_gamma, -1.0, 1.0)) / kRadian;
  return std::hypot(a.theta_i - b.theta_i, gamma);
}

}  // namespace

double ReadingDistance(const IsoDirection& a, const IsoDirection& b) {
  const double to = a.theta_o * kRadian, to2 = b.theta_o * kRadian;
  return DistanceFrom(a, std::cos(to), std::sin(to), b, std::cos(to2), std::sin(to2));
}

namespace {

// Readings per bucket aimed at, and the most buckets along an axis.
constexpr double kPerBucket = 4;
constexpr int kMostBuckets = 1024;
// Slack on a bucket's distance bound, degrees: far above the rounding of ReadingDistance (acos near
// 1 loses up to ~1e-6°), so a bucket is skipped only when every reading in it is strictly farther
// than the k-th nearest.
constexpr double kBoundSlack = 1e-3;

int BucketOf(double theta, double origin, double width, int count) {
  const double b = std::floor((theta - origin) / width);
  return static_cast<int>(std::clamp(b, 0.0, static_cast<double>(count - 1)));
}

// The outgoing direction (θo, φ) as a unit vector: the chord between two of them is at most their
// angle, so hypot(Δθi, chord) bounds a distance from below without trigonometry.
// `cos_o` and `sin_o` are those of d.theta_o in radians (as the caller has them already).
std::array<double, 3> OutgoingUnit(const IsoDirection& d, double cos_o, double sin_o) {
  const double ph = d.phi * kRadian;
  return {sin_o * std::cos(ph), sin_o * std::sin(ph), cos_o};
}

// The gap between `theta` and bucket `b`'s interval along one axis (0 inside it).
double GapTo(double theta, double origin, double width, int b) {
  const double lo = origin + width * b, hi = lo + width;
  return std::max({0.0, lo - theta, theta - hi});
}

// This thread's last query of a ReadingNeighbours (WarmReach).
struct LastQuery {
  std::uint64_t serial = 0;  // the set's; 0: none
  std::size_t k = 0;
  IsoDirection at;
  double cos_o = 1, sin_o = 0;
  double kth = 0;  // its k-th nearest distance
};
thread_local LastQuery last_query;

std::atomic<std::uint64_t> next_serial{1};

}  // namespace

double ReadingNeighbours::WarmReach(const Query& q, std::size_t k) const {
  const LastQuery& last = last_query;
  if (k == 0 || last.serial != serial_ || last.k != k) return kInfinity;
  // The k readings nearest the last query lie within kth + step of this one (the triangle
  // inequality); a slack more covers the rounding of both distances.
  const double step = DistanceFrom(q.at, q.cos_o, q.sin_o, last.at, last.cos_o, last.sin_o);
  return last.kth + step + kBoundSlack;
}

void ReadingNeighbours::RememberQuery(const Query& q, std::size_t k, double kth) const {
  LastQuery& last = last_query;
  last = {std::isfinite(kth) ? serial_ : 0, k, q.at, q.cos_o, q.sin_o, kth};
}

ReadingNeighbours::ReadingNeighbours(const interp::SampleSet& samples) : serial_(next_serial++) {
  const std::size_t n = samples.size();
  double hi_i = 0, hi_o = 0;
  for (std::size_t i = 0; i < n; ++i) {
    const IsoDirection d = At(samples, i);
    theta_i0_ = i == 0 ? d.theta_i : std::min(theta_i0_, d.theta_i);
    theta_o0_ = i == 0 ? d.theta_o : std::min(theta_o0_, d.theta_o);
    hi_i = i == 0 ? d.theta_i : std::max(hi_i, d.theta_i);
    hi_o = i == 0 ? d.theta_o : std::max(hi_o, d.theta_o);
  }
  const double side = std::clamp(std::floor(std::sqrt(static_cast<double>(n) / kPerBucket)), 1.0,
                                 static_cast<double>(kMostBuckets - 1));
  width_ = std::max({hi_i - theta_i0_, hi_o - theta_o0_, 1e-6}) / side;
  rows_ = static_cast<int>((hi_i - theta_i0_) / width_) + 1;
  columns_ = static_cast<int>((hi_o - theta_o0_) / width_) + 1;
  std::vector<std::size_t> bucket(n);
  start_.assign(static_cast<std::size_t>(rows_) * static_cast<std::size_t>(columns_) + 1, 0);
  for (std::size_t i = 0; i < n; ++i) {
    const IsoDirection d = At(samples, i);
    bucket[i] = static_cast<std::size_t>(BucketOf(d.theta_i, theta_i0_, width_, rows_)) *
                    static_cast<std::size_t>(columns_) +
                static_cast<std::size_t>(BucketOf(d.theta_o, theta_o0_, width_, columns_));
    ++start_[bucket[i] + 1];
  }
  for (std::size_t b = 1; b < start_.size(); ++b) start_[b] += start_[b - 1];
  std::vector<std::size_t> next(start_.begin(), start_.end() - 1);
  readings_.resize(n);
  for (std::size_t i = 0; i < n; ++i) {
    const IsoDirection d = At(samples, i);
    const double to = d.theta_o * kRadian;
    const double cos_o = std::cos(to), sin_o = std::sin(to);
    readings_[next[bucket[i]]++] = {{d, cos_o, sin_o, OutgoingUnit(d, cos_o, sin_o)}, i};
  }
}

void ReadingNeighbours::ScanBucket(const Query& q, std::size_t k, double reach, int r, int c,
                                   std::vector<std::pair<double, std::size_t>>* best) const {
  const std::size_t b = static_cast<std::size_t>(r) * static_cast<std::size_t>(columns_) +
                        static_cast<std::size_t>(c);
  for (std::size_t s = start_[b]; s < start_[b + 1]; ++s) {
    const Reading& to = readings_[s];
    const double bound = best->size() == k ? best->back().first : reach;
    if (bound < kInfinity) {
      // Its distance is at least hypot(Δθi, max(|Δθo|, chord)): skip the trigonometry of a
      // reading that bound already puts beyond the k-th nearest, or beyond the query's reach
      // (with kBoundSlack, as buckets).
      const double di = q.at.theta_i - to.at.theta_i;
      const double dx = q.unit[0] - to.unit[0], dy = q.unit[1] - to.unit[1],
                   dz = q.unit[2] - to.unit[2];
      const double chord = std::sqrt(dx * dx + dy * dy + dz * dz) / kRadian;
      const double gamma = std::max(std::abs(q.at.theta_o - to.at.theta_o), chord);
      const double beyond = bound + kBoundSlack;
      if (di * di + gamma * gamma > beyond * beyond) continue;
    }
    const std::pair<double, std::size_t> p(
        DistanceFrom(q.at, q.cos_o, q.sin_o, to.at, to.cos_o, to.sin_o), to.index);
    if (best->size() == k && !(p < best->back())) continue;
    best->insert(std::upper_bound(best->begin(), best->end(), p), p);
    if (best->size() > k) best->pop_back();
  }
}

void ReadingNeighbours::Nearest(const IsoDirection& at, std::size_t k,
                                std::vector<std::size_t>* index,
                                std::vector<double>* distance) const {
  // Ring by ring (Chebyshev, in buckets) around `at`'s bucket: a bucket of ring m is at least
  // (m − 1) widths away along θi or θo, so once that exceeds the k-th nearest, no farther ring can
  // hold a nearer reading. Within a ring, a bucket whose box is farther is skipped.
  // Kept by each thread from query to query (a grid asks one per model cell).
  thread_local std::vector<std::pair<double, std::size_t>> best;
  best.clear();
  const double to = at.theta_o * kRadian;
  const double cos_o = std::cos(to), sin_o = std::sin(to);
  const Query q{at, cos_o, sin_o, OutgoingUnit(at, cos_o, sin_o)};
  const int r0 = BucketOf(at.theta_i, theta_i0_, width_, rows_);
  const int c0 = BucketOf(at.theta_o, theta_o0_, width_, columns_);
  // No reading farther than this can be among the k nearest: the k-th nearest so far, or before
  // there are k the reach the last query gives (infinite without one).
  const double warm = WarmReach(q, k);
  auto limit = [&] { return k > 0 && best.size() == k ? best.back().first : warm; };
  auto visit = [&](int r, int c) {
    if (r < 0 || r >= rows_ || c < 0 || c >= columns_) return;
    const double gap_i = GapTo(at.theta_i, theta_i0_, width_, r);
    const double gap_o = GapTo(at.theta_o, theta_o0_, width_, c);
    // A bucket whose box is beyond the limit (with kBoundSlack, far above the rounding of either
    // side) is skipped: the larger gap first, then both in quadrature, squared (no hypot).
    const double beyond = limit() + kBoundSlack;
    if (std::max(gap_i, gap_o) > beyond) return;
    if (gap_i * gap_i + gap_o * gap_o > beyond * beyond) return;
    ScanBucket(q, k, warm, r, c, &best);
  };
  const int rings = std::max({r0, rows_ - 1 - r0, c0, columns_ - 1 - c0});
  for (int m = 0; m <= rings && k > 0; ++m) {
    if (width_ * (m - 1) - kBoundSlack > limit()) break;
    if (m == 0) {
      visit(r0, c0);
      continue;
    }
    for (int c = c0 - m; c <= c0 + m; ++c) {
      visit(r0 - m, c);
      visit(r0 + m, c);
    }
    for (int r = r0 - m + 1; r <= r0 + m - 1; ++r) {
      visit(r, c0 - m);
      visit(r, c0 + m);
    }
  }
  RememberQuery(q, k, best.size() == k && k > 0 ? best.back().first : kInfinity);
  index->clear();
  distance->clear();
  for (const auto& [d, i] : best) {
    distance->push_back(d);
    index->push_back(i);
  }
}

std::vector<std::vector<double>> ModelResiduals(const fit::CookTorranceFit& model,
                                                const interp::SampleSet& samples) {
  std::vector<std::vector<double>> out(samples.size());
  for (std::size_t i = 0; i < samples.size(); ++i) {
    const IsoDirection at = At(samples, i);
    const std::span<const double> f = samples.spectrum(i);
    out[i] = ModelMinusReading(model, at, f);
  }
  return out;
}

std::vector<std::vector<std::size_t>> ModelFolds(const interp::SampleSet& samples) {
  std::vector<std::vector<std::size_t>> folds(kModelFolds);
  const std::size_t most = uncertainty::kMaxHeldOut / kModelFolds;
  for (const std::size_t i : uncertainty::HeldOutOrder(samples)) {
    const double block = std::floor(samples.coords(i)[0] / kModelBlockDeg);
    const std::size_t f = static_cast<std::size_t>(std::max(0.0, block)) % kModelFolds;
    if (folds[f].size() < most) folds[f].push_back(i);
  }
  std::erase_if(folds, [](const std::vector<std::size_t>& f) { return f.empty(); });
  return folds;
}

std::vector<uncertainty::HeldOutPoint> PredictModelHeldOut(const interp::SampleSet& samples,
                                                           const WavelengthGrid& grid,
                                                           const CallContext& ctx) {
  std::vector<uncertainty::HeldOutPoint> out;
  if (samples.size() < 2) return out;
  for (const std::vector<std::size_t>& fold : ModelFolds(samples)) {
    if (fold.size() < samples.size()) PredictModelFold(samples, fold, grid, ctx, &out);
  }
  return out;
}

uncertainty::InterpolationCalibration CalibrateModel(const interp::SampleSet& samples,
                                                     const WavelengthGrid& grid,
                                                     const CallContext& ctx) {
  uncertainty::CalibrationTarget target;
  target.size_bins = kModelDistanceBins;
  target.beyond = uncertainty::SizeBeyond::kNotEstimated;
  const std::vector<uncertainty::HeldOutPoint> points = PredictModelHeldOut(samples, grid, ctx);
  return uncertainty::FitInterpolationCalibration(points, static_cast<int>(grid.count), target);
}

ModelCellUncertainty::ModelCellUncertainty(
    const interp::SampleSet& samples,
    std::shared_ptr<const std::vector<std::vector<double>>> residuals,
    uncertainty::InterpolationCalibration calibration)
    : neighbours_(std::make_shared<const ReadingNeighbours>(samples)),
      residuals_(std::move(residuals)),
      calibration_(std::move(calibration)) {}

void ModelCellUncertainty::At(const IsoDirection& at, std::span<double> u) const {
  thread_local std::vector<std::size_t> near;
  thread_local std::vector<double> distance;
  neighbours_->Nearest(at, kModelNeighbours, &near, &distance);
  const double d = distance.empty() ? kNaN : distance.front();
  if (calibration_.scale.size() != u.size() || !std::isfinite(d) ||
      uncertainty::BeyondCalibration(calibration_, d)) {
    std::fill(u.begin(), u.end(), kNaN);
    return;
  }
  LocalScale(*residuals_, near, u);
  // c(d) per band: ScaleAt's values, its bin found once per cell.
  uncertainty::ApplyInterpolationCalibration(calibration_, u, d);
}

}  // namespace brdf::exports
