#include "daemon/api/interpolation_uncertainty.h"

#include <cmath>
#include <string>
#include <utility>

#include "core/uncertainty/interpolated.h"

namespace brdf::daemon {

void AddInterpolationUncertainty(const interp::Interpolation& answer, const IndexSnapshot& index,
                                 v1::InterpolationResult* out) {
  if (answer.status != interp::InterpStatus::kOk) return;
  uncertainty::InterpolatedInputs inputs;
  inputs.samples = index.samples.get();
  // Calibrated against the session's held-out readings (index/interpolation_calibration.h).
  inputs.calibration = &index.calibration->Get(index);
  if (index.quantity == Quantity::kBrdf) {
    inputs.budget_of = [&index](std::size_t i) { return index.budgets.at(i); };
  } else {
    inputs.no_budgets = std::string("the readings' budgets are of the BRDF, this answer is ") +
                        QuantityName(index.quantity) + "; ask for quantity BRDF";
  }
  uncertainty::InterpolatedUncertainty found =
      uncertainty::EstimateInterpolatedUncertainty(answer, inputs);
  v1::InterpolationUncertainty* u = out->mutable_uncertainty();
  u->mutable_measurement()->Add(found.measurement.begin(), found.measurement.end());
  u->mutable_shared()->Add(found.shared.begin(), found.shared.end());
  u->mutable_interpolation()->Add(found.interpolation.begin(), found.interpolation.end());
  for (std::string& entry : found.not_estimated) u->add_not_estimated(std::move(entry));
  const bool measured = !found.measurement.empty();
  const bool interpolated = !found.interpolation.empty();
  const int bands = static_cast<int>(answer.spectrum.size());
  google::protobuf::RepeatedField<double>* combined = u->mutable_combined();
  combined->Resize(bands, 0.0);
  for (int k = 0; k < bands; ++k) {
    const double m = measured && k < u->measurement_size() ? u->measurement(k) : 0.0;
    const double i = interpolated && k < u->interpolation_size() ? u->interpolation(k) : 0.0;
    combined->Set(k, std::sqrt(m * m + i * i));
  }
}

}  // namespace brdf::daemon
