// The uncertainty of one interpolated answer (docs/uncertainty.md, "Interpolated values"), the
// same for the API's Interpolate and InterpolateBatch and for the grid export's cells: the
// measurement part blended from the vertices' reading budgets (blend.h: shared terms correlated,
// a reading blended twice counted once), the part of it that is shared, and the interpolation
// term from the vertices' spread about the blend (InterpolationSpread), scaled by the session's
// calibration when there is one (interpolation_calibration.h). Each part is either
// estimated (one value per band) or left empty with the reason in not_estimated: a vertex without
// a budget, an answer of a quantity the budgets are not of, the nearest method (one vertex).
// Pure: no I/O.
#pragma once

#include <cstddef>
#include <functional>
#include <span>
#include <string>
#include <vector>

#include "core/interp/interpolator.h"
#include "core/uncertainty/blend_budget.h"
#include "core/uncertainty/interpolation_calibration.h"

namespace brdf::uncertainty {

// Where an answer's vertices are found, by their position in the interpolator's sample set
// (interp::Vertex::index).
struct InterpolatedInputs {
  // The samples the answer blended (their spectra give the interpolation term).
  const interp::SampleSet* samples = nullptr;
  // Sample i's budget of the answer's quantity in the blend's form (blend_budget.h; null: none,
  // not estimated), built once per reading by whoever keeps the samples (brdfd's index, the grid
  // export's chain). Unset when the answer's quantity has no budgets: then `no_budgets` says
  // why, in not_estimated.
  std::function<const BlendBudget*(std::size_t index)> budget_of;
  std::string no_budgets;
  // The session's calibration of the interpolation term (interpolation_calibration.h): the
  // spread s becomes c(λ)·s(λ). A calibration without a scale: the spread as it is and
  // "interpolation: not calibrated (…)" in not_estimated. Null: the spread as it is, with no note
  // per answer.
  const InterpolationCalibration* calibration = nullptr;
  // False: InterpolatedUncertainty.shared is left empty, for a caller that does not hand it on
  // (a batch not asked for it, a grid's cells); the other parts are the same.
  bool shared = true;
};

// The size h of an answer's cell: the vertices' weighted spread of positions about their weighted
// centre (the query, for barycentric weights), sqrt(Σ wᵢ ‖xᵢ − x̄‖² / Σ wᵢ), in the vertices'
// coordinates (unscaled). 0 for one vertex. The calibration's size bins are of this h.
double CellSize(std::span<const interp::Vertex> vertices);

// One answer's uncertainty per band, standard uncertainties (k = 1) in the answer's unit.
struct InterpolatedUncertainty {
  std::vector<double> measurement;         // empty: not estimated (the reason in not_estimated)
  std::vector<double> shared;              // the shared part of measurement; empty with it, or
                                           // when not asked (InterpolatedInputs.shared)
  std::vector<double> interpolation;       // empty: not estimated
  std::vector<std::string> not_estimated;  // "measurement: …", "interpolation: …", vertices' own
};

// The uncertainty of `answer` (status kOk; any other gives an empty result). The measurement
// part is "measurement: <why>" in not_estimated when the budgets do not apply or do not fit the
// answer's bands; a vertex without a budget is left out of the blend and named (blend.h).
InterpolatedUncertainty EstimateInterpolatedUncertainty(const interp::Interpolation& answer,
                                                        const InterpolatedInputs& inputs);
// The same into `out`, whose vectors are reused (cleared, their capacity kept): a batch's
// thousands of answers allocate nothing for their spectra once they have grown.
void EstimateInterpolatedUncertainty(const interp::Interpolation& answer,
                                     const InterpolatedInputs& inputs,
                                     InterpolatedUncertainty* out);

}  // namespace brdf::uncertainty
