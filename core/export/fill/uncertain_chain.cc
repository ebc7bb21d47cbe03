#include "core/export/fill/uncertain_chain.h"

#include <algorithm>
#include <cmath>
#include <functional>
#include <limits>
#include <memory>
#include <span>
#include <string>
#include <utility>
#include <vector>

#include "core/export/fill/model_uncertainty.h"
#include "core/export/number_text.h"
#include "core/fit/models.h"
#include "core/json_text.h"
#include "core/uncertainty/band_sums.h"
#include "core/uncertainty/blend_budget.h"
#include "core/uncertainty/held_out.h"
#include "core/uncertainty/interpolated.h"
#include "core/uncertainty/loaded_budget.h"

namespace brdf::exports {
namespace {

constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();
constexpr std::size_t kMostNotEstimated = 20;

// Plane `p` of a row of kUncertainPlanes · bands values.
std::span<double> Plane(std::span<double> row, UncertainPlane p, std::size_t bands) {
  return row.subspan(static_cast<std::size_t>(p) * bands, bands);
}

// `from` into `to`, NaN past its end (an empty part: NaN in every band).
void CopyOrNaN(std::span<const double> from, std::span<double> to) {
  const std::size_t n = std::min(from.size(), to.size());
  std::copy_n(from.begin(), n, to.begin());
  std::fill(to.begin() + static_cast<std::ptrdiff_t>(n), to.end(), kNaN);
}

// One answer's row: the value, then its uncertainty planes (NaN where a part is missing).
void WriteAnswer(const interp::Interpolation& answer, const uncertainty::InterpolatedInputs& inputs,
                 std::span<double> row) {
  const std::size_t bands = answer.spectrum.size();
  std::copy(answer.spectrum.begin(), answer.spectrum.end(), row.begin());
  // Kept by each resampling thread from cell to cell: a grid's cells allocate nothing for it.
  thread_local uncertainty::InterpolatedUncertainty u;
  uncertainty::EstimateInterpolatedUncertainty(answer, inputs, &u);
  // A vertex without a budget would leave the blend short: the whole part is NaN, never partial.
  bool every_budget = !u.measurement.empty();
  for (const interp::Vertex& v : answer.vertices) {
    every_budget = every_budget && inputs.budget_of(v.index) != nullptr;
  }
  const std::span<double> m = Plane(row, UncertainPlane::kMeasurement, bands);
  const std::span<double> i = Plane(row, UncertainPlane::kInterpolation, bands);
  const std::span<double> c = Plane(row, UncertainPlane::kCombined, bands);
  // Each plane whole, then c = sqrt(m² + i²) a vector of bands at a time (SqrtBands rounds as
  // std::sqrt does): the same values as band by band.
  CopyOrNaN(every_budget ? std::span<const double>(u.measurement) : std::span<const double>(), m);
  CopyOrNaN(u.interpolation, i);
  for (std::size_t b = 0; b < bands; ++b) c[b] = m[b] * m[b] + i[b] * i[b];
  uncertainty::SqrtBands(c);
}

// An interpolator as a stage answering rows with their uncertainties. Its batch writes only the
// rows it answers (a FillChain stage's contract, not a SpectrumSource's: 4 planes of NaN per row
// the next stage then overwrote were 8 % of an export with uncertainty on the demo session).
SpectrumSource InterpolatorWithUncertainty(const interp::Interpolator& interpolator,
                                           uncertainty::InterpolatedInputs inputs) {
  auto one = [&interpolator, inputs](const IsoDirection& at, std::span<double> out) {
    const double q[3] = {at.theta_i, at.theta_o, at.phi};
    const interp::Interpolation answer = interpolator.Evaluate(q);
    if (answer.status == interp::InterpStatus::kOk) WriteAnswer(answer, inputs, out);
    return answer.status;
  };
  auto many = [&interpolator, inputs](std::span<const double> directions,
                                      std::span<interp::InterpStatus> statuses,
                                      std::span<double> rows) {
    const std::size_t width = statuses.empty() ? 0 : rows.size() / statuses.size();
    interpolator.EvaluateEach(directions, [&](std::size_t k, interp::Interpolation&& answer) {
      statuses[k] = answer.status;
      // A row it does not answer is left as it is (FillChain::Stage: the chain fills NaN where
      // no stage answers; most such rows are the next stage's, which writes them whole).
      if (answer.status == interp::InterpStatus::kOk) {
        WriteAnswer(answer, inputs, rows.subspan(k * width, width));
      }
      return true;
    });
  };
  return SpectrumSource(std::move(one), std::move(many));
}

// The model as a stage: its value, its local uncertainty (model_uncertainty.h: NaN where it is
// not estimated) as the interpolation term and the combined u, no measurement part.
SpectrumSource ModelWithLocalUncertainty(const fit::CookTorranceFit& model,
                                         std::shared_ptr<const ModelCellUncertainty> local) {
  return [params = model.band, local = std::move(local)](const IsoDirection& at,
                                                         std::span<double> row) {
    const std::size_t bands = params.size();
    fit::CookTorranceSpectrumAt(fit::LobeGeometryOf(at), params, row.first(bands));
    const std::span<double> u = Plane(row, UncertainPlane::kInterpolation, bands);
    local->At(at, u);
    std::copy(u.begin(), u.end(), Plane(row, UncertainPlane::kCombined, bands).begin());
    std::fill_n(Plane(row, UncertainPlane::kMeasurement, bands).begin(), bands, kNaN);
    return interp::InterpStatus::kOk;
  };
}

// Sample i's independent part (its budget's); unset for a quantity other than the BRDF (the
// budgets are of the BRDF).
uncertainty::IndependentOf IndependentParts(const SessionInterpolant& in) {
  if (in.derived->quantity != Quantity::kBrdf) return {};
  return [&samples = in.derived->samples](std::size_t i) -> const std::vector<double>* {
    const uncertainty::LoadedBudget* b = i < samples.size() ? samples[i].budget.get() : nullptr;
    return b != nullptr ? &b->blend.independent : nullptr;
  };
}

uncertainty::InterpolationCalibration Calibrate(const SessionInterpolant& in,
                                                interp::Method method) {
  return uncertainty::CalibrateInterpolation(*in.samples, IndependentParts(in), method, in.options,
                                             static_cast<int>(in.derived->grid.count));
}

// Sample i's budget in the blend's form, as brdfd's index keeps them (daemon/index/budgets.h):
// the loaded session's (DerivedSample::budget, made once per reading by the session's
// BlendBudgetMaker when it was loaded), so that a cell's measurement part is the same blend of the
// same values as Interpolate's answer at its direction. Null: the sample has no budget, or one
// whose parts do not all have the same number of bands (not estimated). Unset for a quantity other
// than the BRDF (the budgets are of the BRDF).
std::function<const uncertainty::BlendBudget*(std::size_t)> BlendBudgetsOf(
    const SessionInterpolant& in) {
  if (in.derived->quantity != Quantity::kBrdf) return {};
  return [&samples = in.derived->samples](std::size_t i) -> const uncertainty::BlendBudget* {
    const uncertainty::LoadedBudget* b = i < samples.size() ? samples[i].budget.get() : nullptr;
    return b != nullptr && b->blendable ? &b->blend : nullptr;
  };
}

UncertaintyCoverage CoverageOf(const SessionInterpolant& in) {
  UncertaintyCoverage c;
  c.samples = in.derived->samples.size();
  c.grid = in.derived->grid;
  if (in.derived->quantity != Quantity::kBrdf) {
    c.no_budgets = std::string("the readings' budgets are of the BRDF, this export is of ") +
                   QuantityName(in.derived->quantity) + "; export the BRDF for a measurement part";
    c.without_budget = c.samples;
  }
  for (const DerivedSample& s : in.derived->samples) {
    if (!c.no_budgets.empty()) break;
    if (!s.budget) {
      ++c.without_budget;
      continue;
    }
    for (const std::string& entry : *s.budget->blend.not_estimated) {
      if (c.not_estimated.size() < kMostNotEstimated &&
          std::find(c.not_estimated.begin(), c.not_estimated.end(), entry) ==
              c.not_estimated.end()) {
        c.not_estimated.push_back(entry);
      }
    }
  }
  if (in.model) {
    for (const fit::Residuals& r : in.model->band_residuals) c.model_spread.push_back(r.rms);
  }
  return c;
}

}  // namespace

const char* UncertainPlaneName(UncertainPlane p) {
  switch (p) {
    case UncertainPlane::kValue:
      return "value";
    case UncertainPlane::kCombined:
      return "u";
    case UncertainPlane::kMeasurement:
      return "u_measurement";
    case UncertainPlane::kInterpolation:
      return "u_interpolation";
  }
  return "?";
}

namespace {

const char* PlaneMeaning(UncertainPlane p) {
  switch (p) {
    case UncertainPlane::kCombined:
      return "combined standard uncertainty (k = 1), sqrt(u_measurement^2 + u_interpolation^2); "
             "model cells: the model's local uncertainty alone (model_cells)";
    case UncertainPlane::kMeasurement:
      return "measurement part: the blended vertices' reading budgets, shared terms (white "
             "standard, references, darks, instrument) correlated, as Interpolate gives it";
    case UncertainPlane::kInterpolation:
      return "interpolation term c(lambda) s(lambda): the vertices' weighted spread about the "
             "blend scaled by the session's calibration from held-out readings "
             "(interpolation_calibration), as Interpolate gives it; a stage not calibrated: the "
             "spread as it is; model cells: c(d) times the RMS of the model's residuals at the "
             "nearest readings, c per distance d from the readings fitted on held-out readings "
             "(model_cells); NaN farther from every reading than the calibration reaches";
    case UncertainPlane::kValue:
      break;
  }
  return "the value";
}

std::string JsonList(const std::vector<std::string>& items) {
  std::string j = "[";
  for (std::size_t k = 0; k < items.size(); ++k) j += (k ? ", " : "") + JsonString(items[k]);
  return j + "]";
}

std::string JsonNumbers(const std::vector<double>& values) {
  if (values.empty()) return "null";
  std::string j = "[";
  for (std::size_t k = 0; k < values.size(); ++k) {
    j += (k ? ", " : "") + (std::isfinite(values[k]) ? FormatNumber(values[k]) : "null");
  }
  return j + "]";
}

// A stage's calibration: its method, and its scale per band group or why it has none.
std::string StageCalibrationJson(const StageCalibration& s, const WavelengthGrid& grid) {
  const uncertainty::InterpolationCalibration& fit = s.fit;
  std::string j = std::string("{\"stage\": ") + JsonString(ProvenanceName(s.stage)) +
                  ", \"method\": " + JsonString(interp::MethodName(s.method)) +
                  ", \"calibrated\": " + (fit.scale.empty() ? "false" : "true") +
                  ", \"held_out_readings\": " + std::to_string(fit.held_out);
  if (fit.scale.empty()) {
    return j + ", \"why\": " + JsonString(fit.detail) +
           ", \"instead\": \"the vertices' spread as it is (wider: docs/uncertainty.md)\"}";
  }
  j += ", \"band_groups\": [";
  for (std::size_t g = 0; g < fit.band_groups; ++g) {
    const std::size_t first = uncertainty::BandGroupFirst(g, fit.band_groups, fit.scale.size());
    const std::size_t last = uncertainty::BandGroupFirst(g + 1, fit.band_groups, fit.scale.size());
    if (last <= first) continue;
    j += (g ? ", " : "") + std::string("{\"bands\": [") + std::to_string(first) + ", " +
         std::to_string(last - 1) + "], \"nm\": [" + FormatNumber(grid.at(first)) + ", " +
         FormatNumber(grid.at(last - 1)) + "], \"scale\": " + FormatNumber(fit.scale[first]) + "}";
  }
  return j + "], \"detail\": " + JsonString(fit.detail) + "}";
}

// "interpolation_calibration": calibrated when every interpolating stage is.
std::string CalibrationJson(const UncertaintyCoverage& c) {
  bool calibrated = !c.calibrations.empty();
  std::string stages;
  for (const StageCalibration& s : c.calibrations) {
    calibrated = calibrated && !s.fit.scale.empty();
    stages += (stages.empty() ? "" : ", ") + StageCalibrationJson(s, c.grid);
  }
  const uncertainty::CalibrationTarget target;
  return std::string("{\"calibrated\": ") + (calibrated ? "true" : "false") +
         ", \"what\": \"u_interpolation = c(lambda) s(lambda), c per band group the smallest "
         "scale whose k = " +
         FormatNumber(target.k) + " intervals hold " + FormatNumber(target.coverage) +
         " of the held-out readings' residuals (split-conformal rank), fitted on this session "
         "as Interpolate's is (docs/uncertainty.md, The interpolation term)\", \"stages\": [" +
         stages + "]}";
}

// "model_cells": how the model cells' u is fitted, its scale per distance bin, and the distance
// beyond which it is not estimated; null without a model.
std::string ModelCellsJson(const UncertaintyCoverage& c) {
  if (!c.model_calibration) return "null";
  const uncertainty::InterpolationCalibration& m = *c.model_calibration;
  std::string j = std::string(
                      "{\"what\": \"u = c(d, lambda) rho(lambda): rho the RMS of the "
                      "model's residuals at the ") +
                  std::to_string(kModelNeighbours) +
                  " nearest readings, d the distance in degrees to the nearest reading (incidence "
                  "and the outgoing directions' angle in quadrature), c per band group and "
                  "distance bin fitted on held-out readings (the model refitted without them)\"" +
                  ", \"calibrated\": " + (m.scale.empty() ? "false" : "true") +
                  ", \"held_out_readings\": " + std::to_string(m.held_out);
  if (m.scale.empty()) {
    return j + ", \"why\": " + JsonString(m.detail) + ", \"u\": \"NaN in every model cell\"}";
  }
  j += ", \"not_estimated_beyond_deg\": " + FormatNumber(m.largest_cell) + ", \"bins\": [";
  for (std::size_t i = 0; i <= m.larger.size(); ++i) {
    const std::vector<double>& scale = i == 0 ? m.scale : m.larger[i - 1].scale;
    j += (i ? ", " : "") + std::string("{\"from_deg\": ") +
         FormatNumber(i == 0 ? 0.0 : m.larger[i - 1].above) + ", \"scale\": " + JsonNumbers(scale) +
         "}";
  }
  return j + "], \"detail\": " + JsonString(m.detail) + "}";
}

}  // namespace

std::string UncertaintyJson(const UncertaintyCoverage& c, Quantity quantity,
                            const std::vector<UncertaintyFile>& files) {
  std::string j = "{\"k\": 1, \"kind\": \"standard uncertainty\", \"unit\": " +
                  JsonString(QuantityUnit(quantity)) +
                  ", \"shape\": \"the values' shape, the same cells and bands\", \"arrays\": {";
  for (std::size_t k = 0; k < files.size(); ++k) {
    j += (k ? ", " : "") + JsonString(UncertainPlaneName(files[k].plane)) +
         ": {\"file\": " + JsonString(files[k].file_name) +
         ", \"what\": " + JsonString(PlaneMeaning(files[k].plane)) + "}";
  }
  j += "}, \"nan\": " +
       JsonString(
           "NaN in every array where the value is NaN (no stage of the fill chain had "
           "one); u_measurement (and u) NaN where a blended reading has no uncertainty "
           "budget or the quantity has none, and in model cells; u_interpolation (and u) "
           "NaN for the nearest method (one vertex) and in model cells farther from every "
           "reading than model_cells.not_estimated_beyond_deg (not estimated: nothing "
           "measured says how far off the model is there)");
  j += ", \"samples\": " + std::to_string(c.samples) +
       ", \"samples_without_budget\": " + std::to_string(c.without_budget);
  j += ", \"measurement_not_estimated\": " +
       (c.no_budgets.empty() ? "null" : JsonString(c.no_budgets));
  j += ", \"budgets_not_estimated\": " + JsonList(c.not_estimated);
  j += ", \"model_residual_rms\": " + JsonNumbers(c.model_spread);
  j += ", \"interpolation_calibration\": " + CalibrationJson(c);
  j += ", \"model_cells\": " + ModelCellsJson(c);
  j += ", \"docs\": \"docs/uncertainty.md, Exports\"}";
  return j;
}

std::vector<std::string> UncertaintyWarnings(const UncertaintyCoverage& c) {
  std::vector<std::string> w;
  if (!c.no_budgets.empty()) {
    w.push_back("uncertainty: no measurement part (" + c.no_budgets +
                "); u_measurement and u are NaN, u_interpolation is given");
  } else if (c.without_budget > 0) {
    w.push_back("uncertainty: " + std::to_string(c.without_budget) + " of " +
                std::to_string(c.samples) +
                " sample readings have no uncertainty budget (recorded before budgets, or "
                "[uncertainty] enabled = false): the cells blending them have u_measurement and "
                "u NaN");
  }
  if (c.model_calibration && c.model_calibration->scale.empty()) {
    w.push_back("uncertainty: the model cells' u is not estimated (" + c.model_calibration->detail +
                "): their u_interpolation and u are NaN");
  }
  for (const StageCalibration& s : c.calibrations) {
    if (!s.fit.scale.empty() || s.method == interp::Method::kNearest) continue;
    w.push_back(std::string("uncertainty: the interpolation term of the ") +
                ProvenanceName(s.stage) + " cells (" + interp::MethodName(s.method) +
                ") is not calibrated (" + s.fit.detail +
                "): their u_interpolation is the vertices' spread as it is, wider than a "
                "calibrated term (docs/uncertainty.md)");
  }
  return w;
}

const uncertainty::InterpolationCalibration& ChosenCalibration(const SessionInterpolant& in) {
  return in.calibrations->chosen.Get([&in] { return Calibrate(in, in.method); });
}

const uncertainty::InterpolationCalibration& FallbackCalibration(const SessionInterpolant& in) {
  return in.calibrations->fallback.Get([&in] { return Calibrate(in, interp::Method::kDelaunay); });
}

const uncertainty::InterpolationCalibration& ModelCalibration(const SessionInterpolant& in) {
  return in.calibrations->model.Get([&in] {
    return CalibrateModel(*in.samples, in.derived->grid,
                          CallContext::WithTimeout(kModelCalibrationTimeout));
  });
}

UncertainChain MakeUncertainChain(const SessionInterpolant& in) {
  UncertainChain out;
  out.coverage = CoverageOf(in);
  uncertainty::InterpolatedInputs inputs;
  inputs.samples = in.samples.get();
  inputs.budget_of = BlendBudgetsOf(in);
  inputs.no_budgets = out.coverage.no_budgets;
  inputs.shared = false;  // the grid has no array for it
  // Each interpolating stage's term scaled by its own calibration, as Interpolate's is.
  inputs.calibration = &ChosenCalibration(in);
  out.coverage.calibrations.push_back({Provenance::kInterpolated, in.method, *inputs.calibration});
  std::vector<FillChain::Stage> stages;
  stages.push_back(
      {Provenance::kInterpolated, InterpolatorWithUncertainty(*in.interpolator, inputs)});
  if (in.fallback) {
    inputs.calibration = &FallbackCalibration(in);
    out.coverage.calibrations.push_back(
        {Provenance::kFallback, interp::Method::kDelaunay, *inputs.calibration});
    stages.push_back({Provenance::kFallback, InterpolatorWithUncertainty(*in.fallback, inputs)});
  }
  if (in.model) {
    out.coverage.model_calibration = ModelCalibration(in);
    auto residuals = std::make_shared<const std::vector<std::vector<double>>>(
        ModelResiduals(*in.model, *in.samples));
    auto local = std::make_shared<const ModelCellUncertainty>(*in.samples, std::move(residuals),
                                                              *out.coverage.model_calibration);
    stages.push_back({Provenance::kModel, ModelWithLocalUncertainty(*in.model, std::move(local))});
  }
  out.chain = std::make_unique<FillChain>(in.chain->Tally().policy, std::move(stages));
  return out;
}

}  // namespace brdf::exports
