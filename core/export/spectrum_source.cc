#include "core/export/spectrum_source.h"

#include <algorithm>
#include <atomic>
#include <cstdint>
#include <memory>

#include "core/geometry.h"

namespace brdf::exports {

SpectrumSource InterpolatorSource(const interp::Interpolator& interpolator) {
  // Grids and MERL tables need no provenance: SpectrumAt answers the same spectrum without
  // allocating, which is most of a grid's cost. It writes the sample set's band count, which the
  // interface does not expose, so the first answer through Evaluate learns it; every later call
  // whose buffer has exactly that many bands takes the fast path.
  auto bands = std::make_shared<std::atomic<std::int64_t>>(-1);
  return [&interpolator, bands](const IsoDirection& at, std::span<double> out) {
    const double query[3] = {at.theta_i, at.theta_o, at.phi};
    if (bands->load(std::memory_order_relaxed) == static_cast<std::int64_t>(out.size())) {
      return interpolator.SpectrumAt(query, out);
    }
    const interp::Interpolation result = interpolator.Evaluate(query);
    if (result.status != interp::InterpStatus::kOk) return result.status;
    bands->store(static_cast<std::int64_t>(result.spectrum.size()), std::memory_order_relaxed);
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
