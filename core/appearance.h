// What a measured sample looks like: its colour, and a sphere of it lit by a distant light, in
// sRGB under an illuminant (CIE D65, CIE illuminant A), computed from its spectral BRDF f_r(λ)
// (sr⁻¹) on the meter's wavelength grid. Pure: the BRDF comes as a lookup over isotropic
// directions (in brdfd the session's interpolant behind the fill chain), the illuminant and the
// colour-matching functions as spectra (data/cie_tables.h reads them).
//
// Sample colour: the reflectance factor R(λ) = π·f_r(λ) at the CIE 45°:0° geometry (CIE 15:
// illumination at 45° from the normal, viewing along the normal; here θi = 45°, θo = 0°, φ = 0°)
// → CIE XYZ under the illuminant (core/colorimetry: ReflectanceToXyz, Y = 1 for the perfect
// white) → xy → linear sRGB (IEC 61966-2-1) → 8-bit sRGB.
//
// Lit sphere: a unit sphere seen orthographically along its axis (+z towards the viewer, x to
// the right, y up; pixel centres, row 0 at the top), lit by a distant light from `light` (not
// necessarily unit; the default is the Python client's figure's, upper left in front). At each
// pixel inside the disc the normal n gives the local directions: θi from n·light, θo from n·view,
// φ between the two directions' projections on the tangent plane (180° = the mirror side), as
// core/geometry's isotropic reduction. The pixel's radiance is f_r(λ)·S(λ)·cos θi; its XYZ is
// taken with the same normalisation as the sample colour times π, so that ONE exposure rule holds
// for every pixel and illuminant: a white Lambertian (f_r = 1/π) lit head-on has Y = 1 (and sRGB
// 255, 255, 255 under D65). Brighter pixels (a specular highlight) clip to 255 per channel.
// Pixels outside the disc are transparent (alpha 0); pixels whose light is below their horizon
// (cos θi ≤ 0) are opaque black; every pixel inside the disc is opaque.
//
// Anisotropic samples are outside this module: the lookup takes isotropic directions (brdfd
// refuses anisotropic sessions before it gets here).
#pragma once

#include <array>
#include <cstddef>
#include <cstdint>
#include <functional>
#include <span>
#include <string>
#include <vector>

#include "core/colorimetry.h"
#include "core/pose.h"
#include "core/spectrum.h"
#include "core/status.h"
#include "core/wavelength_grid.h"

namespace brdf {

// The BRDF (sr⁻¹) at an isotropic direction: writes one value per band of the grid into `out`
// and returns true, or returns false when it has no value there (out left alone). Called from
// one thread.
using BrdfLookup = std::function<bool(const IsoDirection& at, std::span<double> out)>;

// CIE standard illuminant A on `grid`: Planck's law at 2856 K in the CIE 15 form
//   S_A(λ) = 100 · (560/λ)⁵ · (exp(c2 / (2848 · 560)) − 1) / (exp(c2 / (2848 · λ)) − 1),
// c2 = 1.435 × 10⁷ nm·K (λ in nm; 100 at 560 nm). Valid for any positive wavelengths.
Spectrum CieIlluminantA(const WavelengthGrid& grid);

// The CIE 45°:0° geometry of the sample colour.
inline constexpr IsoDirection kColourGeometry{45, 0, 0};

struct SampleColour {
  Spectrum reflectance;  // R(λ) = π·f_r(λ) at 45°:0°
  Xyz xyz;               // Y = 1 for the perfect white
  Chromaticity xy;       // (0, 0) for black
  Rgb linear_srgb;       // unclipped: out-of-gamut colours leave [0, 1]
  std::array<std::uint8_t, 3> srgb8{};
  std::string hex;  // "#rrggbb"
};

// The sample's colour under `illuminant`. Errors: the lookup has no value at 45°:0°
// (kFailedPrecondition), an illuminant or CMF table that does not cover the grid, an invalid grid.
Result<SampleColour> ComputeSampleColour(const BrdfLookup& brdf, const WavelengthGrid& grid,
                                         const Spectrum& illuminant,
                                         const ColorMatchingFunctions& cmf);

struct SphereOptions {
  int size = 128;                                // pixels per side, 1 … kMaxSphereSize
  std::array<double, 3> light{-0.5, 0.6, 0.62};  // towards the light; any non-zero length
};
inline constexpr int kMaxSphereSize = 512;

struct LitSphere {
  int size = 0;
  std::vector<std::uint8_t> rgba;  // size × size × 4, row-major from the top row
  std::size_t disc_pixels = 0;     // pixels inside the disc
  std::size_t unlit_pixels = 0;    // of those, light below the horizon (black)
  std::size_t missing_pixels = 0;  // lit, but the lookup had no value (black)
  double peak_y = 0;               // the largest pixel Y (> 1: clipped somewhere)
};

// Errors (kInvalidArgument): a size outside 1 … kMaxSphereSize, a light of zero or non-finite
// length, an invalid grid or one the illuminant / CMFs do not cover.
Result<LitSphere> RenderLitSphere(const BrdfLookup& brdf, const WavelengthGrid& grid,
                                  const Spectrum& illuminant, const ColorMatchingFunctions& cmf,
                                  const SphereOptions& options);

// "#rrggbb" of 8-bit components.
std::string HexColour(const std::array<std::uint8_t, 3>& rgb);

}  // namespace brdf
