// Where a resampled export (regular grid, MERL table) gets its spectra: anything that answers a
// spectrum at an isotropic direction (θi, θo, φ). In brdfd that is the session's interpolator; in
// tests and the synthetic demo, a known analytic BRDF.
#pragma once

#include <functional>
#include <span>

#include "core/analytic_brdf.h"
#include "core/interp/interpolator.h"
#include "core/pose.h"
#include "core/wavelength_grid.h"

namespace brdf::exports {

// Writes one value per band into `out` (out.size() = bands) and returns kOk, or returns why there
// is no value (and leaves `out` alone). Called from many threads at once: must be thread-safe.
using SpectrumSource =
    std::function<interp::InterpStatus(const IsoDirection& at, std::span<double> out)>;

// Asks a 3D interpolator. The interpolator must outlive the source.
SpectrumSource InterpolatorSource(const interp::Interpolator& interpolator);

// Evaluates an analytic BRDF (sr⁻¹) on `grid` at CanonicalDirections(at); always kOk.
SpectrumSource AnalyticSource(const AnalyticBrdf& brdf, const WavelengthGrid& grid);

}  // namespace brdf::exports
