#include "daemon/api/interpolation_uncertainty.h"

#include <cmath>
#include <memory>
#include <string>
#include <utility>
#include <vector>

#include "core/uncertainty/interpolated.h"

namespace brdf::daemon {
namespace {

// `values` as the API's single-precision spectrum `out` (its previous values replaced).
void SetFloats(const std::vector<double>& values, google::protobuf::RepeatedField<float>* out) {
  out->Resize(static_cast<int>(values.size()), 0.0f);
  float* to = out->mutable_data();
  for (std::size_t k = 0; k < values.size(); ++k) to[k] = static_cast<float>(values[k]);
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

// Where the answer's vertices' budgets and spectra are, and the snapshot's calibration.
uncertainty::InterpolatedInputs InputsOf(const IndexSnapshot& index) {
  uncertainty::InterpolatedInputs inputs;
  inputs.samples = index.samples.get();
  if (index.quantity == Quantity::kBrdf) {
    inputs.budget_of = [&index](std::size_t i) { return index.budgets.at(i); };
  } else {
    inputs.no_budgets = std::string("the readings' budgets are of the BRDF, this answer is ") +
                        QuantityName(index.quantity) + "; ask for quantity BRDF";
  }
  // Calibrated against the session's held-out readings (index/interpolation_calibration.h).
  inputs.calibration = &index.calibration->Get(index);
  return inputs;
}

// `entries` as u's not_estimated.
void SetNotEstimated(const std::vector<std::string>& entries, v1::InterpolationUncertainty* u) {
  google::protobuf::RepeatedPtrField<std::string>* to = u->mutable_not_estimated();
  for (const std::string& entry : entries) to->Add()->assign(entry);
}

}  // namespace

void AddInterpolationUncertainty(const interp::Interpolation& answer, const IndexSnapshot& index,
                                 UncertaintyParts parts, v1::InterpolationResult* out) {
  if (answer.status != interp::InterpStatus::kOk) return;
  // Kept by each thread from answer to answer: a batch allocates nothing for its spectra.
  thread_local uncertainty::InterpolatedUncertainty found;
  uncertainty::InterpolatedInputs inputs = InputsOf(index);
  inputs.shared = parts.shared;
  uncertainty::EstimateInterpolatedUncertainty(answer, inputs, &found);
  v1::InterpolationUncertainty* u = out->mutable_uncertainty();
  SetFloats(found.measurement, u->mutable_measurement());
  if (parts.shared) SetFloats(found.shared, u->mutable_shared());
  SetFloats(found.interpolation, u->mutable_interpolation());
  SetNotEstimated(found.not_estimated, u);
  if (parts.combined) AddCombined(static_cast<int>(answer.spectrum.size()), u);
}

}  // namespace brdf::daemon
