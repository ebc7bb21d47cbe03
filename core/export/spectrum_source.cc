#include "core/export/spectrum_source.h"

#include <algorithm>

#include "core/geometry.h"

namespace brdf::exports {

SpectrumSource InterpolatorSource(const interp::Interpolator& interpolator) {
  return [&interpolator](const IsoDirection& at, std::span<double> out) {
    const double query[3] = {at.theta_i, at.theta_o, at.phi};
    const interp::Interpolation result = interpolator.Evaluate(query);
    if (result.status != interp::InterpStatus::kOk) return result.status;
    std::copy_n(result.spectrum.begin(), std::min(out.size(), result.spectrum.size()), out.begin());
    return interp::InterpStatus::kOk;
  };
}

SpectrumSource AnalyticSource(const AnalyticBrdf& brdf, const WavelengthGrid& grid) {
  return [brdf, grid](const IsoDirection& at, std::span<double> out) {
    brdf.EvaluateSpectrum(CanonicalDirections(at), grid, out);
    return interp::InterpStatus::kOk;
  };
}

}  // namespace brdf::exports
