#include "drivers/spectroradiometer.h"

namespace brdf::drivers {

Result<MeasuredSpectrum> Spectroradiometer::MeasureSpectrum(const CallContext& ctx,
                                                            const MeasuredCallback& measured) {
  BRDF_ASSIGN_OR_RETURN(MeasurementOutcome outcome, Measure(ctx));
  if (measured) measured(outcome);
  BRDF_ASSIGN_OR_RETURN(SpectrumReport report, TransferSpectrum(ctx));
  return MeasuredSpectrum{std::move(outcome), std::move(report)};
}

}  // namespace brdf::drivers
