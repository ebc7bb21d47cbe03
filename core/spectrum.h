// Spectra on a wavelength grid, and the two quantities a session derives from raw readings
// (docs/geometry.md, "Reflectance and BRDF"):
//   reflectance R(λ) = (I(λ) − D(λ)) / (I0(λ) − D(λ))        (the paper's I/I0, D optional)
//   BRDF        f(λ) = R(λ) · ρw(λ) / π · cos θi,ref / cos θi  (sr⁻¹)
// where I is the sample's radiance at a pose, I0 the white standard's at the reference pose
// (incidence θi,ref), D an optional dark reading and ρw the white standard's reflectance.
// Pure; the raw readings stay stored so that both quantities can be recomputed.
#pragma once

#include <string>
#include <vector>

#include "core/status.h"
#include "core/wavelength_grid.h"

namespace brdf {

// One value per band of `grid` (values.size() == grid.count). Units depend on the use: radiance
// (W·m⁻²·sr⁻¹·nm⁻¹) for a reading, unitless for a reflectance, sr⁻¹ for a BRDF.
struct Spectrum {
  WavelengthGrid grid;
  std::vector<double> values;
  friend bool operator==(const Spectrum&, const Spectrum&) = default;
};

// The paper's white standard (RS-3): ρw = 0.99 ± 0.01, flat and Lambertian.
inline constexpr double kWhiteStandardReflectance = 0.99;

// Checks that the grid is valid, that there is one value per band and that every value is finite.
// `what` names the spectrum in the message ("sample reading", "white reference", ...).
// A grid in the operator's words: "380–780 nm every 4 nm (101 bands)".
std::string GridText(const WavelengthGrid& g);

Status ValidateSpectrum(const Spectrum& s, const std::string& what);

// R = I / I0, or (I − D) / (I0 − D) with a dark reading. Errors (kInvalidArgument): an invalid
// spectrum, grids that differ, a band where I0 (− D) ≤ 0 (named by wavelength and index: the
// reference is too dark there to divide by). A slightly negative I − D (noise in a dark band) is
// kept as is.
Result<Spectrum> Reflectance(const Spectrum& sample, const Spectrum& white);
Result<Spectrum> Reflectance(const Spectrum& sample, const Spectrum& white, const Spectrum& dark);

// f = R · ρw / π · cos θi,ref / cos θi, with ρw per band or constant. Errors: an invalid spectrum,
// grids that differ, ρw ≤ 0 or non-finite, θi or θi,ref outside [0°, 90°) (the cosine ratio is
// undefined at grazing incidence).
Result<Spectrum> BrdfFromReflectance(const Spectrum& reflectance, const Spectrum& white_reflectance,
                                     double theta_i_ref_deg, double theta_i_deg);
Result<Spectrum> BrdfFromReflectance(const Spectrum& reflectance, double white_reflectance,
                                     double theta_i_ref_deg, double theta_i_deg);

// The inverse, R = f · π / ρw · cos θi / cos θi,ref: what a white-referenced measurement of a
// known BRDF reads (the simulator's virtual sample). Same errors.
Result<Spectrum> ReflectanceFromBrdf(const Spectrum& brdf, double white_reflectance,
                                     double theta_i_ref_deg, double theta_i_deg);

// Linear interpolation onto another grid. Every target wavelength must lie within the source's
// range (no extrapolation; 1e-9 nm slack), otherwise kInvalidArgument naming the wavelength.
Result<Spectrum> Resample(const Spectrum& s, const WavelengthGrid& target);

}  // namespace brdf
