// Colour of a measured spectrum: CIE XYZ, xy chromaticity and sRGB, from a reflectance spectrum
// under an illuminant, with colour-matching functions passed in as tables. Also a parser for the
// spectral tables colord-data ships (/usr/share/colord/{cmf,illuminant,ref}/*.{cmf,sp}, CGATS
// text as written by cd-it8). Pure: the parser takes the file's text, callers read the file.
#pragma once

#include <string>
#include <string_view>
#include <vector>

#include "core/spectrum.h"
#include "core/status.h"

namespace brdf {

// A parsed CGATS spectral file: one or more sets of values over the SPEC_<nm> fields.
struct SpectralTable {
  std::string kind;                       // the file's first keyword: "SPECT", "CMF"
  std::string name;                       // DISPLAY (e.g. "CIE-D65"), empty when absent
  std::vector<double> wavelengths_nm;     // from the SPEC_<nm> fields, in file order
  std::vector<std::string> set_ids;       // SAMPLE_ID of each set; empty when the file has none
  std::vector<std::vector<double>> sets;  // sets[i][k] is the value at wavelengths_nm[k]

  // Set `index` as a Spectrum. Errors: no such set, or wavelengths that are not evenly spaced
  // and increasing (a Spectrum lives on a regular grid).
  Result<Spectrum> SetAsSpectrum(std::size_t index) const;
};

// Parses the text of a colord spectral file. The wavelengths come from SPECTRAL_START_NM,
// SPECTRAL_END_NM and SPECTRAL_BANDS when all three are present (evenly spaced; colord's CIE-A.sp
// names its fields in thousandths of a nm, so the names cannot be trusted), else from the
// SPEC_<nm> field names. Keywords other than those, DISPLAY, NUMBER_OF_FIELDS and
// NUMBER_OF_SETS are read and ignored; lines starting with '#' are comments. Fields other than
// SPEC_<nm> and SAMPLE_ID are skipped. Errors (kInvalidArgument) name the line and say what is
// wrong: missing BEGIN_DATA_FORMAT / BEGIN_DATA sections, no SPEC_ fields, a value that is not a
// number, a value count that does not fill whole sets, a set count other than NUMBER_OF_SETS.
Result<SpectralTable> ParseSpectralTable(std::string_view text);

// x̄, ȳ, z̄ on one grid.
struct ColorMatchingFunctions {
  Spectrum x_bar;
  Spectrum y_bar;
  Spectrum z_bar;
};

// The three sets of a CMF table (x̄, ȳ, z̄ in that order, as in colord's CIE1931-2deg-XYZ.cmf).
Result<ColorMatchingFunctions> ColorMatchingFunctionsFromTable(const SpectralTable& table);

struct Xyz {
  double X = 0, Y = 0, Z = 0;
};
struct Chromaticity {
  double x = 0, y = 0;
};
struct Rgb {
  double r = 0, g = 0, b = 0;
};

// Tristimulus values of a reflectance R under illuminant S: X = k Σ R S x̄, Y = k Σ R S ȳ,
// Z = k Σ R S z̄ over the reflectance's bands, with k = 1 / Σ S ȳ so that the perfect white
// (R = 1) has Y = 1. The illuminant and the CMFs are resampled linearly onto the reflectance's
// grid, which they must cover (no extrapolation); bands outside the reflectance's range do not
// contribute. Errors: invalid spectra, a grid not covered, an illuminant with Σ S ȳ ≤ 0.
Result<Xyz> ReflectanceToXyz(const Spectrum& reflectance, const Spectrum& illuminant,
                             const ColorMatchingFunctions& cmf);

// The illuminant's white point on `grid`: ReflectanceToXyz of R = 1.
Result<Xyz> WhitePoint(const Spectrum& illuminant, const ColorMatchingFunctions& cmf,
                       const WavelengthGrid& grid);

// x = X / (X + Y + Z), y = Y / (X + Y + Z). Error when X + Y + Z ≤ 0 (black has no chromaticity).
Result<Chromaticity> ToChromaticity(const Xyz& xyz);

// Linear sRGB (IEC 61966-2-1, D65 white, primaries' matrix) from XYZ with Y = 1 for white. No
// chromatic adaptation: the XYZ should be taken under D65 for the sRGB to mean what it says.
// Out-of-gamut colours give components outside [0, 1].
Rgb XyzToLinearSrgb(const Xyz& xyz);

// The sRGB transfer function on one component, clamped to [0, 1] first.
double EncodeSrgbComponent(double linear);
Rgb EncodeSrgb(const Rgb& linear);

}  // namespace brdf
