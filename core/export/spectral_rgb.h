// Linear sRGB of a spectral BRDF (or reflectance) under an illuminant, as one weight triple per
// band: RGB = Σ_b value_b · w_b. The weights come from core/colorimetry itself (ReflectanceToXyz
// of a unit impulse in each band, then XyzToLinearSrgb); both steps are linear, so applying the
// weights gives exactly what colorimetry gives for the whole spectrum, at a fraction of the cost
// (a MERL export converts about 700,000 spectra). A BRDF of 1/π sr⁻¹ in every band (a white
// Lambertian) gives RGB ≈ (1/π, 1/π, 1/π) under D65.
#pragma once

#include <span>
#include <vector>

#include "core/colorimetry.h"
#include "core/status.h"
#include "core/wavelength_grid.h"

namespace brdf::exports {

class SpectralRgbWeights {
 public:
  // Errors: those of ReflectanceToXyz (an invalid grid, an illuminant or CMF table that does not
  // cover `grid`).
  static Result<SpectralRgbWeights> Make(const WavelengthGrid& grid, const Spectrum& illuminant,
                                         const ColorMatchingFunctions& cmf);

  const WavelengthGrid& grid() const { return grid_; }
  // values.size() must be grid().count.
  Rgb Apply(std::span<const double> values) const;

 private:
  WavelengthGrid grid_;
  std::vector<Rgb> weights_;  // one per band
};

}  // namespace brdf::exports
