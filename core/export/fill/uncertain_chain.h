// The fill chain of a session's interpolant answering each direction with its uncertainty, for
// exports that carry one (the grid's .npy with `include_uncertainty`; docs/uncertainty.md,
// "Exports"). A cell's row holds kUncertainPlanes planes of `bands` values each:
//   value          the interpolated (or modelled) quantity, as the plain chain gives it;
//   u              the combined standard uncertainty (k = 1), sqrt(u_measurement² +
//                  u_interpolation²); for a model cell its residual spread alone;
//   u_measurement  the vertices' budgets blended (core/uncertainty/interpolated.h, the same as
//                  the Interpolate API), NaN when a vertex has no budget or the quantity has none
//                  (only the BRDF has budgets), and for model cells;
//   u_interpolation the interpolation term c(λ)·s(λ): the vertices' spread about the blend
//                  (InterpolationSpread) scaled by the stage's calibration from held-out readings
//                  (uncertainty/held_out.h), as the Interpolate API gives it (the spread as it is
//                  where the stage could not be calibrated); for model cells the model's local
//                  uncertainty (fill/model_uncertainty.h: the residuals of the nearest readings
//                  scaled by a calibration per distance from the readings, NaN farther than it
//                  reaches); NaN for the nearest method (one vertex).
// NaN in every plane where no stage has a value. One pass: the values and their uncertainties
// come from the same answers (Interpolator::EvaluateEach). Pure: no I/O.
#pragma once

#include <cstddef>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "core/export/fill/chain.h"
#include "core/export/fill/session_interpolant.h"
#include "core/uncertainty/interpolation_calibration.h"
#include "core/wavelength_grid.h"

namespace brdf::exports {

inline constexpr std::size_t kUncertainPlanes = 4;
enum class UncertainPlane { kValue = 0, kCombined = 1, kMeasurement = 2, kInterpolation = 3 };
const char* UncertainPlaneName(UncertainPlane p);  // "value", "u", "u_measurement", …

// The interpolation term's calibration of one interpolating stage of the chain.
struct StageCalibration {
  Provenance stage = Provenance::kInterpolated;  // kInterpolated (the chosen method) or kFallback
  interp::Method method = interp::Method::kOctant;
  uncertainty::InterpolationCalibration fit;  // empty scale: not calibrated (fit.detail: why)
};

// What the session's samples give the uncertainty, for the sidecar and the report's warnings.
struct UncertaintyCoverage {
  std::size_t samples = 0;
  std::size_t without_budget = 0;  // sample readings with no budget of this quantity
  std::string no_budgets;          // non-empty: the quantity has no budgets at all, and why
  // The union of the samples' budgets' not_estimated entries (each once, at most 20).
  std::vector<std::string> not_estimated;
  std::vector<double> model_spread;  // per band, the model's residual RMS; empty without a model
  // The model cells' calibration (fill/model_uncertainty.h); unset without a model.
  std::optional<uncertainty::InterpolationCalibration> model_calibration;
  WavelengthGrid grid;                         // the bands (the calibration's band groups in nm)
  std::vector<StageCalibration> calibrations;  // the chosen method's, then the fallback's
};

// The interpolation term's calibration of `in`'s chosen method and of its fallback (which `in`
// must have) over its samples and their budgets, as the Interpolate API calibrates the same
// session's index: computed by the first caller for `in`'s parts and kept with them
// (SessionInterpolant::calibrations), so that every export sharing them reuses it.
const uncertainty::InterpolationCalibration& ChosenCalibration(const SessionInterpolant& in);
const uncertainty::InterpolationCalibration& FallbackCalibration(const SessionInterpolant& in);
// The model cells' calibration (fill/model_uncertainty.h, CalibrateModel), kept likewise; `in`
// must have a model.
const uncertainty::InterpolationCalibration& ModelCalibration(const SessionInterpolant& in);

// A FillChain over `in`'s stages (the chosen method, its Delaunay fallback and its model, as
// `in.chain` has them) whose sources answer rows of kUncertainPlanes · bands values. `in` must
// outlive it. Its Tally() counts the cells as in.chain's would.
struct UncertainChain {
  std::unique_ptr<FillChain> chain;
  UncertaintyCoverage coverage;
};
UncertainChain MakeUncertainChain(const SessionInterpolant& in);

// The uncertainty arrays written beside an export, one per plane other than the value.
struct UncertaintyFile {
  UncertainPlane plane = UncertainPlane::kCombined;
  std::string file_name;  // e.g. "session-3-grid-brdf.u.npy"
};

// The sidecar's "uncertainty" object (a JSON object, no trailing newline): k = 1, the unit of
// `quantity`, each file and what it holds, which cells are NaN and why, the coverage (samples
// without a budget, what the budgets leave out, the model's residual RMS per band) and the
// interpolation term's calibration ("interpolation_calibration": "calibrated", and per stage its
// method, held-out readings and scale per band group, or why it is not calibrated).
std::string UncertaintyJson(const UncertaintyCoverage& coverage, Quantity quantity,
                            const std::vector<UncertaintyFile>& files);

// The report's warnings for `coverage`: samples without a budget (their cells' u_measurement
// and u NaN), a quantity without budgets, an interpolating stage whose term is not calibrated.
// Empty when every sample has a budget and every stage is calibrated.
std::vector<std::string> UncertaintyWarnings(const UncertaintyCoverage& coverage);

}  // namespace brdf::exports
