#include "daemon/api/interpolation_uncertainty.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <span>
#include <string>
#include <vector>

#include "core/uncertainty/blend.h"
#include "core/uncertainty/interpolation_calibration.h"

namespace brdf::daemon {
namespace {

// Room for an answer's vertices without allocating (octant: 4 or 5; Delaunay: dims + 1); a
// larger answer goes to the heap.
constexpr std::size_t kInline = 8;

template <typename T>
struct Scratch {
  std::array<T, kInline> inline_items{};
  std::vector<T> heap;
  std::span<T> Take(std::size_t n) {
    if (n <= kInline) return {inline_items.data(), n};
    heap.resize(n);
    return heap;
  }
};

// What one answer's uncertainty is computed in, kept by each thread from answer to answer: a
// batch's thousands of answers allocate nothing for their spectra once it has grown.
struct AnswerScratch {
  uncertainty::BlendedUncertainty blended;
  std::vector<double> spread;
};

AnswerScratch& ThreadScratch() {
  thread_local AnswerScratch scratch;
  return scratch;
}

// `values` as the API's single-precision spectrum `out` (its previous values replaced).
void SetFloats(const std::vector<double>& values, google::protobuf::RepeatedField<float>* out) {
  out->Resize(static_cast<int>(values.size()), 0.0f);
  float* to = out->mutable_data();
  for (std::size_t k = 0; k < values.size(); ++k) to[k] = static_cast<float>(values[k]);
}

// The measurement part into `u` (the shared part too with parts.shared); false (with the reason
// in not_estimated) when there is none.
bool AddMeasurement(const interp::Interpolation& answer, const IndexSnapshot& index,
                    UncertaintyParts parts, v1::InterpolationUncertainty* u) {
  if (index.quantity != Quantity::kBrdf) {
    u->add_not_estimated(std::string("measurement: the readings' budgets are of the BRDF, this "
                                     "answer is ") +
                         QuantityName(index.quantity) + "; ask for quantity BRDF");
    return false;
  }
  Scratch<uncertainty::BlendVertex> scratch;
  const std::span<uncertainty::BlendVertex> vertices = scratch.Take(answer.vertices.size());
  for (std::size_t i = 0; i < vertices.size(); ++i) {
    const interp::Vertex& v = answer.vertices[i];
    vertices[i] = {v.id, v.weight, index.budgets.at(v.index)};
  }
  uncertainty::BlendedUncertainty& blended = ThreadScratch().blended;
  const Status st = uncertainty::BlendMeasurementUncertainty(vertices, index.grid.count, &blended);
  if (!st.ok()) {
    u->add_not_estimated("measurement: " + st.message());
    return false;
  }
  SetFloats(blended.measurement, u->mutable_measurement());
  if (parts.shared) SetFloats(blended.shared, u->mutable_shared());
  for (std::string& entry : blended.not_estimated) u->add_not_estimated(std::move(entry));
  return true;
}

// The interpolation term into `u`; false (with the reason) when there is none.
bool AddInterpolation(const interp::Interpolation& answer, const IndexSnapshot& index,
                      v1::InterpolationUncertainty* u) {
  if (answer.method == interp::Method::kNearest) {
    u->add_not_estimated(
        "interpolation: the nearest method blends one reading, so its spread says nothing; use "
        "octant or delaunay for an estimate");
    return false;
  }
  Scratch<double> weight_scratch;
  Scratch<std::span<const double>> spectrum_scratch;
  const std::span<double> weights = weight_scratch.Take(answer.vertices.size());
  const std::span<std::span<const double>> spectra = spectrum_scratch.Take(weights.size());
  for (std::size_t i = 0; i < weights.size(); ++i) {
    weights[i] = answer.vertices[i].weight;
    spectra[i] = index.samples->spectrum(answer.vertices[i].index);
  }
  std::vector<double>& spread = ThreadScratch().spread;
  uncertainty::InterpolationSpread(weights, spectra, answer.spectrum, &spread);
  // Calibrated against the session's held-out readings (index/interpolation_calibration.h).
  const uncertainty::InterpolationCalibration& calibration = index.calibration->Get(index);
  if (!uncertainty::ApplyInterpolationCalibration(calibration, spread)) {
    u->add_not_estimated("interpolation: not calibrated (" + calibration.detail +
                         "); the vertices' spread as it is");
  }
  SetFloats(spread, u->mutable_interpolation());
  return true;
}

// combined = sqrt(m² + i²) per band from the parts as sent (floats; a part not estimated is
// empty and counts 0), in double, rounded to float: what a client computes from them.
void AddCombined(int bands, v1::InterpolationUncertainty* u) {
  google::protobuf::RepeatedField<float>* combined = u->mutable_combined();
  combined->Resize(bands, 0.0f);
  for (int k = 0; k < bands; ++k) {
    const double m = k < u->measurement_size() ? u->measurement(k) : 0.0;
    const double i = k < u->interpolation_size() ? u->interpolation(k) : 0.0;
    combined->Set(k, static_cast<float>(std::sqrt(m * m + i * i)));
  }
}

}  // namespace

void AddInterpolationUncertainty(const interp::Interpolation& answer, const IndexSnapshot& index,
                                 UncertaintyParts parts, v1::InterpolationResult* out) {
  if (answer.status != interp::InterpStatus::kOk) return;
  v1::InterpolationUncertainty* u = out->mutable_uncertainty();
  AddMeasurement(answer, index, parts, u);
  AddInterpolation(answer, index, u);
  if (parts.combined) AddCombined(static_cast<int>(answer.spectrum.size()), u);
}

}  // namespace brdf::daemon
