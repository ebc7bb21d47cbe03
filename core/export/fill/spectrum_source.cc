#include "core/export/fill/spectrum_source.h"

#include <algorithm>
#include <limits>

#include "core/geometry.h"

namespace brdf::exports {

void SpectrumSource::Spectra(std::span<const double> directions,
                             std::span<interp::InterpStatus> statuses,
                             std::span<double> spectra) const {
  const std::size_t n = statuses.size();
  if (n == 0) return;
  if (many_) {
    many_(directions, statuses, spectra);
    return;
  }
  const std::size_t bands = spectra.size() / n;
  for (std::size_t i = 0; i < n; ++i) {
    const std::span<double> row = spectra.subspan(i * bands, bands);
    const IsoDirection at{directions[3 * i], directions[3 * i + 1], directions[3 * i + 2]};
    statuses[i] = one_(at, row);
    if (statuses[i] != interp::InterpStatus::kOk) {
      std::fill(row.begin(), row.end(), std::numeric_limits<double>::quiet_NaN());
    }
  }
}

SpectrumSource InterpolatorSource(const interp::Interpolator& interpolator) {
  // Grids and MERL tables need no provenance: SpectrumAt and SpectraAt answer the same spectrum
  // as Evaluate without allocating (every method writes min(bands, out.size()) values), which is
  // most of a grid's cost.
  return SpectrumSource(
      [&interpolator](const IsoDirection& at, std::span<double> out) {
        const double query[3] = {at.theta_i, at.theta_o, at.phi};
        return interpolator.SpectrumAt(query, out);
      },
      [&interpolator](std::span<const double> directions, std::span<interp::InterpStatus> statuses,
                      std::span<double> spectra) {
        interpolator.SpectraAt(directions, statuses, spectra);
      });
}

SpectrumSource AnalyticSource(const AnalyticBrdf& brdf, const WavelengthGrid& grid) {
  return [brdf, grid](const IsoDirection& at, std::span<double> out) {
    brdf.EvaluateSpectrum(CanonicalDirections(at), grid, out);
    return interp::InterpStatus::kOk;
  };
}

}  // namespace brdf::exports
