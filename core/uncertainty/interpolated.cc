#include "core/uncertainty/interpolated.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <span>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

#include "core/uncertainty/blend.h"
#include "core/uncertainty/note_list.h"

namespace brdf::uncertainty {
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

// The blend of the answer's vertices with their budgets (`budget_of` gives a vertex's, by its
// position in the sample set) into `blended`.
Status BlendVertices(const interp::Interpolation& answer,
                     const std::function<const BlendBudget*(std::size_t)>& budget_of, bool shared,
                     BlendedUncertainty& blended) {
  Scratch<BlendVertex> scratch;
  const std::span<BlendVertex> vertices = scratch.Take(answer.vertices.size());
  for (std::size_t i = 0; i < vertices.size(); ++i) {
    const interp::Vertex& v = answer.vertices[i];
    vertices[i] = {v.id, v.weight, budget_of(v.index)};
  }
  return BlendMeasurementUncertainty(std::span<const BlendVertex>(vertices),
                                     static_cast<int>(answer.spectrum.size()), &blended, shared);
}

// The measurement part into `out`, or the reason it has none.
void AddMeasurement(const interp::Interpolation& answer, const InterpolatedInputs& inputs,
                    InterpolatedUncertainty& out, NoteList& notes) {
  if (!inputs.budget_of) {
    notes.Add("measurement: " + inputs.no_budgets);
    return;
  }
  // The blend's working storage, kept by each thread: a batch's answers allocate nothing once it
  // has grown (the vectors are swapped with `out`'s, so both keep their capacity).
  thread_local BlendedUncertainty blended;
  const Status st = BlendVertices(answer, inputs.budget_of, inputs.shared, blended);
  if (!st.ok()) {
    notes.Add("measurement: " + st.message());
    return;
  }
  std::swap(out.measurement, blended.measurement);
  std::swap(out.shared, blended.shared);
  for (const std::string& entry : blended.not_estimated) notes.Add(entry);
}

// The interpolation term into `out`, or the reason it has none.
void AddInterpolation(const interp::Interpolation& answer, const InterpolatedInputs& inputs,
                      InterpolatedUncertainty& out, NoteList& notes) {
  if (answer.method == interp::Method::kNearest) {
    notes.Add(
        "interpolation: the nearest method blends one reading, so its spread says nothing; use "
        "octant or delaunay for an estimate");
    return;
  }
  Scratch<double> weight_scratch;
  Scratch<std::span<const double>> spectrum_scratch;
  const std::span<double> weights = weight_scratch.Take(answer.vertices.size());
  const std::span<std::span<const double>> spectra = spectrum_scratch.Take(weights.size());
  for (std::size_t i = 0; i < weights.size(); ++i) {
    weights[i] = answer.vertices[i].weight;
    spectra[i] = inputs.samples->spectrum(answer.vertices[i].index);
  }
  InterpolationSpread(weights, spectra, answer.spectrum, &out.interpolation);
  const InterpolationCalibration* calibration = inputs.calibration;
  if (calibration == nullptr) return;
  const double h = calibration->largest_cell > 0 ? CellSize(answer.vertices) : 0.0;
  if (BeyondCalibration(*calibration, h)) {
    out.interpolation.clear();
    notes.Add("interpolation: the cell is larger than every held-out reading's (not estimated)");
  } else if (!ApplyInterpolationCalibration(*calibration, out.interpolation, h)) {
    notes.Add("interpolation: not calibrated (" + calibration->detail +
              "); the vertices' spread as it is");
  }
}

}  // namespace

double CellSize(std::span<const interp::Vertex> vertices) {
  // A cell's coordinates are the interpolant's (3 or 4); more are left out of its size.
  std::array<double, 8> centre{};
  const std::size_t dims =
      vertices.empty() ? 0 : std::min(centre.size(), vertices[0].coords.size());
  double total = 0;
  for (const interp::Vertex& v : vertices) {
    for (std::size_t d = 0; d < dims && d < v.coords.size(); ++d)
      centre[d] += v.weight * v.coords[d];
    total += v.weight;
  }
  if (!(total > 0)) return 0;
  double sum = 0;
  for (const interp::Vertex& v : vertices) {
    double d2 = 0;
    for (std::size_t d = 0; d < dims && d < v.coords.size(); ++d) {
      const double delta = v.coords[d] - centre[d] / total;
      d2 += delta * delta;
    }
    sum += v.weight * d2;
  }
  return std::sqrt(std::max(0.0, sum / total));
}

void EstimateInterpolatedUncertainty(const interp::Interpolation& answer,
                                     const InterpolatedInputs& inputs,
                                     InterpolatedUncertainty* out) {
  out->measurement.clear();
  out->shared.clear();
  out->interpolation.clear();
  NoteList notes(out->not_estimated);
  if (answer.status == interp::InterpStatus::kOk) {
    AddMeasurement(answer, inputs, *out, notes);
    AddInterpolation(answer, inputs, *out, notes);
  }
  notes.Finish();
}

InterpolatedUncertainty EstimateInterpolatedUncertainty(const interp::Interpolation& answer,
                                                        const InterpolatedInputs& inputs) {
  InterpolatedUncertainty out;
  EstimateInterpolatedUncertainty(answer, inputs, &out);
  return out;
}

}  // namespace brdf::uncertainty
