#include "drivers/spectroradiometer.h"

namespace brdf::drivers {

Result<MeasuredSpectrum> Spectroradiometer::MeasureSpectrum(const CallContext& ctx,
                                                            const MeasuredCallback& measured) {
  Result<MeasurementOutcome> outcome = Measure(ctx);
  if (!outcome.ok()) return outcome.status();
  if (measured) measured(*outcome);
  Result<SpectrumReport> report = TransferSpectrum(ctx);
  if (!report.ok()) return report.status();
  return MeasuredSpectrum{std::move(*outcome), std::move(*report)};
}

}  // namespace brdf::drivers
