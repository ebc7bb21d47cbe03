#include "core/adaptive/judged_readings.h"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <limits>
#include <utility>

#include "core/adaptive/interpolated_model.h"
#include "core/geometry.h"
#include "core/interp/octant/octant.h"
#include "core/uncertainty/blend.h"
#include "core/uncertainty/interpolation_calibration.h"

namespace brdf::adaptive {
namespace {

constexpr std::size_t kMaxHeldOut = 300;
constexpr std::size_t kMaxFolds = 32;
constexpr std::size_t kMaxFoldSamplesOctant = 60000;
constexpr std::size_t kMaxFoldSamplesDelaunay = 10000;

interp::Method MethodOf(Judge judge) {
  return judge == Judge::kDelaunay ? interp::Method::kDelaunay : interp::Method::kOctant;
}

bool Usable(const ReadingSoFar& r) {
  const Directions& d = r.directions;
  return std::isfinite(d.theta_i) && std::isfinite(d.phi_i) && std::isfinite(d.theta_o) &&
         std::isfinite(d.phi_o) && std::isfinite(r.brdf) && std::isfinite(r.relative_uncertainty) &&
         r.relative_uncertainty >= 0;
}

// The method's index over `samples` (the octant method: the k-d tree alone, the same answers
// without the grid shortcut's build time); null when it cannot be built.
std::unique_ptr<interp::Interpolator> BuildIndex(std::shared_ptr<const interp::SampleSet> samples,
                                                 interp::Method method) {
  if (samples->size() == 0) return nullptr;
  if (method == interp::Method::kOctant) {
    auto octant = interp::OctantInterpolator::Create(std::move(samples), JudgeOptions(),
                                                     interp::OctantInterpolator::Search::kTree);
    return octant.ok() ? std::move(*octant) : nullptr;
  }
  auto index = interp::MakeInterpolator(method, std::move(samples), JudgeOptions());
  return index.ok() ? std::move(*index) : nullptr;
}

// splitmix64 of a reading's position: the folds do not follow the plan's order.
std::uint64_t Mix(std::uint64_t z) {
  z += 0x9e3779b97f4a7c15ULL;
  z = (z ^ (z >> 30)) * 0xbf58476d1ce4e5b9ULL;
  z = (z ^ (z >> 27)) * 0x94d049bb133111ebULL;
  return z ^ (z >> 31);
}

// The answer's vertices' weights and values, and its blend's measurement part (absolute).
double MeasurementPart(const interp::Interpolation& answer, const interp::SampleSet& set,
                       std::span<const double> relative_u, std::vector<double>* weights,
                       std::vector<std::span<const double>>* values) {
  weights->clear();
  values->clear();
  double u2 = 0;
  for (const interp::Vertex& v : answer.vertices) {
    weights->push_back(v.weight);
    values->push_back(set.spectrum(v.index));
    const double u = v.weight * relative_u[v.index] * set.spectrum(v.index)[0];
    u2 += u * u;
  }
  return std::sqrt(u2);
}

// One fold held out: an index over the rest predicts each held reading at its own point.
void PredictFold(const interp::SampleSet& all, std::span<const double> relative_u,
                 std::span<const std::size_t> held, interp::Method method,
                 std::vector<uncertainty::HeldOutPoint>* out) {
  std::vector<bool> is_held(all.size(), false);
  for (std::size_t j : held) is_held[j] = true;
  auto rest = std::make_shared<interp::SampleSet>(all.dims(), all.bands());
  std::vector<double> rest_u;
  for (std::size_t i = 0; i < all.size(); ++i) {
    if (is_held[i] || !rest->Add(all.id(i), all.coords(i), all.spectrum(i)).ok()) continue;
    rest_u.push_back(relative_u[i]);
  }
  const std::unique_ptr<interp::Interpolator> index = BuildIndex(rest, method);
  if (index == nullptr) return;
  std::vector<double> weights;
  std::vector<std::span<const double>> values;
  for (std::size_t j : held) {
    const interp::Interpolation answer = index->Evaluate(all.coords(j));
    if (answer.status != interp::InterpStatus::kOk || answer.spectrum.size() != 1) continue;
    const double truth = all.spectrum(j)[0];
    const double noise_vertices = MeasurementPart(answer, *rest, rest_u, &weights, &values);
    const double noise_own = relative_u[j] * truth;
    uncertainty::HeldOutPoint point;
    point.residual = {answer.spectrum[0] - truth};
    point.spread = uncertainty::InterpolationSpread(weights, values, answer.spectrum);
    point.noise = {std::hypot(noise_own, noise_vertices)};
    out->push_back(std::move(point));
  }
}

// The held-out predictions, in folds bounded as the daemon's (judged_readings.h).
std::vector<uncertainty::HeldOutPoint> PredictHeldOut(const interp::SampleSet& all,
                                                      std::span<const double> relative_u,
                                                      interp::Method method) {
  std::vector<uncertainty::HeldOutPoint> out;
  const std::size_t n = all.size();
  if (n < 2) return out;
  const std::size_t cap =
      method == interp::Method::kOctant ? kMaxFoldSamplesOctant : kMaxFoldSamplesDelaunay;
  const std::size_t folds = std::clamp<std::size_t>(cap / n, 1, std::min(kMaxFolds, n));
  const std::size_t fold =
      std::max<std::size_t>(1, std::min((n + folds - 1) / folds, kMaxHeldOut / folds));
  std::vector<std::pair<std::uint64_t, std::size_t>> keyed(n);
  for (std::size_t i = 0; i < n; ++i) keyed[i] = {Mix(i), i};
  std::sort(keyed.begin(), keyed.end());
  std::vector<std::size_t> order(n);
  for (std::size_t i = 0; i < n; ++i) order[i] = keyed[i].second;
  for (std::size_t f = 0; f < folds && f * fold < n; ++f) {
    const std::size_t end = std::min(n, (f + 1) * fold);
    PredictFold(all, relative_u, std::span(order).subspan(f * fold, end - f * fold), method, &out);
  }
  return out;
}

}  // namespace

JudgedReadings::JudgedReadings(std::span<const ReadingSoFar> readings, Judge judge)
    : samples_(std::make_shared<interp::SampleSet>(3, 1)) {
  for (const ReadingSoFar& r : readings) {
    if (!Usable(r)) continue;
    const IsoDirection iso = ToIsotropic(r.directions);
    const double coords[3] = {iso.theta_i, iso.theta_o, iso.phi};
    const double value[1] = {r.brdf};
    if (!samples_->Add(static_cast<std::int64_t>(relative_u_.size()), coords, value).ok()) continue;
    relative_u_.push_back(r.relative_uncertainty);
  }
  interp::Method method = MethodOf(judge);
  index_ = BuildIndex(samples_, method);
  if (index_ == nullptr && method != interp::Method::kOctant) {
    method = interp::Method::kOctant;
    index_ = BuildIndex(samples_, method);
  }
  if (index_ == nullptr) return;
  const std::vector<uncertainty::HeldOutPoint> points =
      PredictHeldOut(*samples_, relative_u_, method);
  held_out_ = points.size();
  const uncertainty::InterpolationCalibration fit =
      uncertainty::FitInterpolationCalibration(points, 1, uncertainty::CalibrationTarget{});
  if (fit.scale.size() == 1 && std::isfinite(fit.scale[0])) {
    scale_ = fit.scale[0];
    calibrated_ = true;
  }
}

JudgedReadings::~JudgedReadings() = default;

std::optional<JudgedAnswer> JudgedReadings::Answer(const std::array<double, 3>& point) const {
  if (index_ == nullptr) return std::nullopt;
  const interp::Interpolation answer = index_->Evaluate(point);
  if (answer.status != interp::InterpStatus::kOk || answer.spectrum.size() != 1) {
    return std::nullopt;
  }
  JudgedAnswer out;
  std::vector<double> weights;
  std::vector<std::span<const double>> values;
  out.value = answer.spectrum[0];
  out.u_measurement = MeasurementPart(answer, *samples_, relative_u_, &weights, &values);
  out.u_interpolation =
      scale_ * uncertainty::InterpolationSpread(weights, values, answer.spectrum)[0];
  for (const interp::Vertex& v : answer.vertices) {
    if (v.coords.size() == 3) out.vertices.push_back({v.coords[0], v.coords[1], v.coords[2]});
  }
  return out;
}

std::array<double, 8> JudgedReadings::OrthantNearest2(const std::array<double, 3>& point) const {
  std::array<double, 8> best;
  best.fill(std::numeric_limits<double>::infinity());
  for (std::size_t i = 0; i < samples_->size(); ++i) {
    const std::span<const double> c = samples_->coords(i);
    const double d0 = c[0] - point[0], d1 = c[1] - point[1];
    const int side = (d0 >= 0 ? 1 : 0) | (d1 >= 0 ? 2 : 0);
    for (double phi : {c[2], -c[2], 360 - c[2]}) {
      const double d2 = phi - point[2];
      const int o = side | (d2 >= 0 ? 4 : 0);
      best[o] = std::min(best[o], d0 * d0 + d1 * d1 + d2 * d2);
    }
  }
  return best;
}

double JudgedReadings::MeanSquareValue() const {
  if (samples_->size() == 0) return 0;
  double sum = 0;
  for (std::size_t i = 0; i < samples_->size(); ++i) {
    sum += samples_->spectrum(i)[0] * samples_->spectrum(i)[0];
  }
  return sum / static_cast<double>(samples_->size());
}

}  // namespace brdf::adaptive
