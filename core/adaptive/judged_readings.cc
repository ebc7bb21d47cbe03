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
#include "core/uncertainty/held_out.h"
#include "core/uncertainty/interpolation_calibration.h"

namespace brdf::adaptive {
namespace {

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

// The answer's vertices' weights and values, and its blend's measurement part (absolute). A
// reading blended more than once (its mirror images in φ keep its index) is one reading, as in
// the daemon's blend (core/uncertainty/blend.h): its weights are summed before its noise is
// squared, since its copies carry the same error.
double MeasurementPart(const interp::Interpolation& answer, const interp::SampleSet& set,
                       std::span<const double> relative_u, std::vector<double>* weights,
                       std::vector<std::span<const double>>* values) {
  weights->clear();
  values->clear();
  std::vector<std::pair<std::size_t, double>> per_reading;  // index, summed weight
  for (const interp::Vertex& v : answer.vertices) {
    weights->push_back(v.weight);
    values->push_back(set.spectrum(v.index));
    auto same = std::find_if(per_reading.begin(), per_reading.end(),
                             [&v](const auto& r) { return r.first == v.index; });
    if (same == per_reading.end()) {
      per_reading.emplace_back(v.index, v.weight);
    } else {
      same->second += v.weight;
    }
  }
  double u2 = 0;
  for (const auto& [index, weight] : per_reading) {
    const double u = weight * relative_u[index] * set.spectrum(index)[0];
    u2 += u * u;
  }
  return std::sqrt(u2);
}

// Each reading's measurement noise as held_out.h reads it: a one-band independent part, the
// reading's relative u times its BRDF (absolute).
std::vector<std::vector<double>> ScalarNoise(const interp::SampleSet& samples,
                                             std::span<const double> relative_u) {
  std::vector<std::vector<double>> noise(samples.size());
  for (std::size_t i = 0; i < samples.size(); ++i) {
    noise[i] = {relative_u[i] * samples.spectrum(i)[0]};
  }
  return noise;
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
  // Held out as the daemon's calibration is (held_out.h): folds by a hash of the sample ids,
  // which are the readings' positions here.
  const std::vector<std::vector<double>> noise = ScalarNoise(*samples_, relative_u_);
  const std::vector<uncertainty::HeldOutPoint> points = uncertainty::PredictHeldOut(
      *samples_, [&noise](std::size_t i) { return &noise[i]; }, method, JudgeOptions());
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
