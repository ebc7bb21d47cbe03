#include "daemon/api/interpolation_uncertainty.h"

#include <cmath>
#include <span>
#include <string>
#include <vector>

#include "core/uncertainty/blend.h"

namespace brdf::daemon {
namespace {

// The measurement part into `u`; false (with the reason in not_estimated) when there is none.
bool AddMeasurement(const interp::Interpolation& answer, const IndexSnapshot& index,
                    v1::InterpolationUncertainty* u) {
  if (index.quantity != Quantity::kBrdf) {
    u->add_not_estimated(std::string("measurement: the readings' budgets are of the BRDF, this "
                                     "answer is ") +
                         QuantityName(index.quantity) + "; ask for quantity BRDF");
    return false;
  }
  std::vector<uncertainty::BlendVertex> vertices;
  vertices.reserve(answer.vertices.size());
  for (const interp::Vertex& v : answer.vertices) {
    vertices.push_back({v.id, v.weight, index.budgets.at(v.index)});
  }
  Result<uncertainty::BlendedUncertainty> blended =
      uncertainty::BlendMeasurementUncertainty(vertices, index.grid.count);
  if (!blended.ok()) {
    u->add_not_estimated("measurement: " + blended.status().message());
    return false;
  }
  u->mutable_measurement()->Add(blended->measurement.begin(), blended->measurement.end());
  u->mutable_shared()->Add(blended->shared.begin(), blended->shared.end());
  for (std::string& entry : blended->not_estimated) u->add_not_estimated(std::move(entry));
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
  std::vector<double> weights;
  std::vector<std::span<const double>> spectra;
  weights.reserve(answer.vertices.size());
  spectra.reserve(answer.vertices.size());
  for (const interp::Vertex& v : answer.vertices) {
    weights.push_back(v.weight);
    spectra.push_back(index.samples->spectrum(v.index));
  }
  const std::vector<double> spread =
      uncertainty::InterpolationSpread(weights, spectra, answer.spectrum);
  u->mutable_interpolation()->Add(spread.begin(), spread.end());
  return true;
}

}  // namespace

void AddInterpolationUncertainty(const interp::Interpolation& answer, const IndexSnapshot& index,
                                 v1::InterpolationResult* out) {
  if (answer.status != interp::InterpStatus::kOk) return;
  v1::InterpolationUncertainty* u = out->mutable_uncertainty();
  const bool measured = AddMeasurement(answer, index, u);
  const bool interpolated = AddInterpolation(answer, index, u);
  const std::size_t bands = answer.spectrum.size();
  u->mutable_combined()->Reserve(static_cast<int>(bands));
  for (std::size_t k = 0; k < bands; ++k) {
    const double m = measured ? u->measurement(static_cast<int>(k)) : 0.0;
    const double i = interpolated ? u->interpolation(static_cast<int>(k)) : 0.0;
    u->add_combined(std::hypot(m, i));
  }
}

}  // namespace brdf::daemon
