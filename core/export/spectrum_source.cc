#include "core/export/spectrum_source.h"

#include "core/geometry.h"

namespace brdf::exports {

SpectrumSource InterpolatorSource(const interp::Interpolator& interpolator) {
  // Grids and MERL tables need no provenance: SpectrumAt answers the same spectrum as Evaluate
  // without allocating (every method writes min(bands, out.size()) values), which is most of a
  // grid's cost.
  return [&interpolator](const IsoDirection& at, std::span<double> out) {
    const double query[3] = {at.theta_i, at.theta_o, at.phi};
    return interpolator.SpectrumAt(query, out);
  };
}

SpectrumSource AnalyticSource(const AnalyticBrdf& brdf, const WavelengthGrid& grid) {
  return [brdf, grid](const IsoDirection& at, std::span<double> out) {
    brdf.EvaluateSpectrum(CanonicalDirections(at), grid, out);
    return interp::InterpStatus::kOk;
  };
}

}  // namespace brdf::exports
