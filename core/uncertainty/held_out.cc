#include "core/uncertainty/held_out.h"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <memory>
#include <span>
#include <utility>

#include "core/interp/octant/octant.h"
#include "core/uncertainty/blend.h"
#include "core/uncertainty/interpolated.h"

namespace brdf::uncertainty {
namespace {

// splitmix64: a fixed, well-mixed hash of a reading id (the folds do not follow the plan's order).
std::uint64_t Mix(std::int64_t id) {
  std::uint64_t z = static_cast<std::uint64_t>(id) + 0x9e3779b97f4a7c15ULL;
  z = (z ^ (z >> 30)) * 0xbf58476d1ce4e5b9ULL;
  z = (z ^ (z >> 27)) * 0x94d049bb133111ebULL;
  return z ^ (z >> 31);
}

}  // namespace

std::vector<std::size_t> HeldOutOrder(const interp::SampleSet& samples) {
  std::vector<std::pair<std::uint64_t, std::size_t>> keyed(samples.size());
  for (std::size_t i = 0; i < samples.size(); ++i) keyed[i] = {Mix(samples.id(i)), i};
  std::sort(keyed.begin(), keyed.end());
  std::vector<std::size_t> order(keyed.size());
  for (std::size_t i = 0; i < keyed.size(); ++i) order[i] = keyed[i].second;
  return order;
}

namespace {

const std::vector<double>* Independent(const IndependentOf& independent_of, std::size_t i) {
  return independent_of ? independent_of(i) : nullptr;
}

// One held-out sample predicted by `interpolator` over `rest` (rest_to_all: rest's positions in
// the full set); false when the answer is not OK.
bool PredictOne(const interp::SampleSet& samples, const IndependentOf& independent_of,
                std::size_t j, const interp::Interpolator& interpolator,
                const interp::SampleSet& rest, const std::vector<std::size_t>& rest_to_all,
                HeldOutPoint* out) {
  interp::Interpolation answer = interpolator.Evaluate(samples.coords(j));
  if (answer.status != interp::InterpStatus::kOk) return false;
  const std::span<const double> truth = samples.spectrum(j);
  const std::size_t bands = truth.size();
  if (answer.spectrum.size() != bands) return false;
  std::vector<double> weights;
  std::vector<std::span<const double>> spectra;
  for (const interp::Vertex& v : answer.vertices) {
    weights.push_back(v.weight);
    spectra.push_back(rest.spectrum(v.index));
  }
  out->residual.resize(bands);
  for (std::size_t b = 0; b < bands; ++b) out->residual[b] = answer.spectrum[b] - truth[b];
  out->spread = InterpolationSpread(weights, spectra, answer.spectrum);
  out->cell_size = CellSize(answer.vertices);
  out->noise.clear();
  const std::vector<double>* own = Independent(independent_of, j);
  if (own == nullptr || own->size() != bands) return true;
  out->noise.assign(own->begin(), own->end());
  for (double& n : out->noise) n *= n;
  for (const interp::Vertex& v : answer.vertices) {
    const std::vector<double>* u = Independent(independent_of, rest_to_all[v.index]);
    if (u == nullptr || u->size() != bands) continue;
    for (std::size_t b = 0; b < bands; ++b)
      out->noise[b] += v.weight * v.weight * (*u)[b] * (*u)[b];
  }
  for (double& n : out->noise) n = std::sqrt(n);
  return true;
}

// A fold's index: the method's own, except that a plain octant index gets the tree alone (the
// grid shortcut costs up to seconds to build for a few thousand queries; same answers).
Result<std::unique_ptr<interp::Interpolator>> MakeFoldIndex(
    std::shared_ptr<const interp::SampleSet> rest, interp::Method method,
    const interp::Options& options) {
  if (method == interp::Method::kOctant && options.trend == interp::Trend::kNone &&
      options.coordinates == interp::Coordinates::kIncidence) {
    BRDF_ASSIGN_OR_RETURN(std::unique_ptr<interp::OctantInterpolator> octant,
                          interp::OctantInterpolator::Create(
                              std::move(rest), options, interp::OctantInterpolator::Search::kTree));
    return std::unique_ptr<interp::Interpolator>(std::move(octant));
  }
  return interp::MakeInterpolator(method, std::move(rest), options);
}

// One fold: an index over every sample not in `held`, evaluated at each held one.
void PredictFold(const interp::SampleSet& samples, const IndependentOf& independent_of,
                 std::span<const std::size_t> held, interp::Method method,
                 const interp::Options& options, std::vector<HeldOutPoint>* out) {
  std::vector<bool> is_held(samples.size(), false);
  for (std::size_t j : held) is_held[j] = true;
  auto rest = std::make_shared<interp::SampleSet>(samples.dims(), samples.bands());
  std::vector<std::size_t> rest_to_all;
  rest_to_all.reserve(samples.size() - held.size());
  for (std::size_t i = 0; i < samples.size(); ++i) {
    if (is_held[i]) continue;
    if (!rest->Add(samples.id(i), samples.coords(i), samples.spectrum(i)).ok()) return;
    rest_to_all.push_back(i);
  }
  Result<std::unique_ptr<interp::Interpolator>> interpolator = MakeFoldIndex(rest, method, options);
  if (!interpolator.ok()) return;  // e.g. too few readings left for Delaunay: no points
  HeldOutPoint point;
  for (std::size_t j : held) {
    if (PredictOne(samples, independent_of, j, **interpolator, *rest, rest_to_all, &point)) {
      out->push_back(point);
    }
  }
}

}  // namespace

std::vector<HeldOutPoint> PredictHeldOut(const interp::SampleSet& samples,
                                         const IndependentOf& independent_of, interp::Method method,
                                         const interp::Options& options) {
  std::vector<HeldOutPoint> out;
  const std::size_t n = samples.size();
  if (n < 2) return out;
  const std::size_t budget =
      method == interp::Method::kOctant ? kMaxFoldSamplesOctant : kMaxFoldSamplesOther;
  const std::size_t folds = std::clamp<std::size_t>(budget / n, 1, std::min(kMaxFolds, n));
  const std::size_t fold =
      std::max<std::size_t>(1, std::min((n + folds - 1) / folds, kMaxHeldOut / folds));
  const std::vector<std::size_t> order = HeldOutOrder(samples);
  for (std::size_t f = 0; f < folds && f * fold < n; ++f) {
    const std::size_t end = std::min(n, (f + 1) * fold);
    PredictFold(samples, independent_of, std::span(order).subspan(f * fold, end - f * fold), method,
                options, &out);
  }
  return out;
}

CalibrationTarget TargetOf(interp::Method method) {
  CalibrationTarget target;
  if (method == interp::Method::kDelaunay) target.size_bins = kDelaunaySizeBins;
  return target;
}

InterpolationCalibration CalibrateInterpolation(const interp::SampleSet& samples,
                                                const IndependentOf& independent_of,
                                                interp::Method method,
                                                const interp::Options& options, int bands) {
  if (method == interp::Method::kNearest) {
    InterpolationCalibration none;
    none.detail = "the nearest method has no interpolation term";
    return none;
  }
  const std::vector<HeldOutPoint> points = PredictHeldOut(samples, independent_of, method, options);
  return FitInterpolationCalibration(points, bands, TargetOf(method));
}

}  // namespace brdf::uncertainty
