// The meter's side of the PR-650 text protocol, for the simulator: how the meter formats its
// numbers and reports, and how it checks a setup (S) command. Written independently of the
// driver's parser on purpose: the simulator stands in for the device, so it must not share the
// code it is used to test.
#pragma once

#include <string>
#include <string_view>
#include <vector>

#include "core/wavelength_grid.h"
#include "tools/brdf-sim/sim_shared.h"

namespace brdf::sim {

// The PR-650 band layout: 101 bands, 380–780 nm, 4 nm apart, 8 nm bandwidth.
inline constexpr int kPr650Bands = 101;
inline constexpr int kPr650FirstNm = 380;
inline constexpr int kPr650StepNm = 4;

// "1.234E-02": the meter's 9-character number. Values too small for a 2-digit exponent print as
// 0.000E+00, too large ones as 9.999E+99; a negative value carries a leading '-' (10 characters).
std::string FormatPr650Number(double value);

// The D5 report as lines without line ends: "qq,U", the integrated intensity, then one
// "0380.,r.rrrEsee" line per band. `radiance` is padded with zeros or cut to 101 bands.
std::vector<std::string> Pr650SpectrumLines(int quality_code, int units_code, double integrated,
                                            const std::vector<double>& radiance);

// CIE 1931 tristimulus values of a spectral radiance on the PR-650 grid (W·m⁻²·sr⁻¹·nm⁻¹ in,
// cd/m² for Y out: 683 lm/W × Σ L(λ) ȳ(λ) × 4 nm). The colour-matching functions are the
// multi-lobe Gaussian fit of Wyman, Sloan & Shirley (JCGT 2(2), 2013), within a few percent of the
// CIE tables: a simulated meter needs plausible colorimetry, not a calibration.
struct Pr650Tristimulus {
  double X = 0, Y = 0, Z = 0;
};
Pr650Tristimulus Pr650TristimulusOf(const std::vector<double>& radiance);
// The same on any grid (the PR-670's 2 nm, the CS-2000's 1 nm).
Pr650Tristimulus TristimulusOf(const std::vector<double>& radiance, const WavelengthGrid& grid);

// The colorimetric reports, one line each, as the open PR-650 programs parse them:
//   1  "qq,U,Y.YYYEsee,.xxxx,.yyyy"      luminance and CIE 1931 x, y
//   2  "qq,U,X.XXXEsee,Y.YYYEsee,Z.ZZZEsee"  tristimulus values
//   3  "qq,U,Y.YYYEsee,.uuuu,.vvvv"      luminance and CIE 1976 u', v'
//   4  "qq,U,Y.YYYEsee,T.TTTEsee,+.dddd" luminance, correlated colour temperature in K and the
//                                        distance from the Planckian locus in CIE 1960 uv
//                                        (positive above it); the digits of T and d are
//                                        brdf-sim's choice (the sources give the fields only)
//   6  "qq,U,Y.YYYEsee,.xxxx,.yyyy,.uuuu,.vvvv"  luminance, x, y, u', v'
// Chromaticities are 4 decimals with no leading 0; black (X + Y + Z = 0) gives .0000 (and a
// temperature of 0). `report` is 1, 2, 3, 4 or 6; any other number returns an empty string.
std::string Pr650ColorimetryLine(int report, int quality_code, int units_code,
                                 const Pr650Tristimulus& xyz);

// Correlated colour temperature (K) of chromaticity x, y (McCamy's cubic, good to a few K between
// 2,000 and 12,500 K) and its signed distance from the Planckian locus in CIE 1960 uv (Krystek's
// rational fit of the locus).
struct Pr650ColourTemperature {
  double kelvin = 0;
  double duv = 0;
};
Pr650ColourTemperature Pr650ColourTemperatureOf(double x, double y);

// The D120 layout line: "0101,008.0,0380.,0780.,004.".
std::string Pr650LayoutLine();

// The outcome of an S command.
struct Pr650SetupResult {
  int reply_code = 0;  // 0 accepted; 1–8 (9: too many fields) position of the bad field; 50
                       // accessory not fitted
  MeterSetup setup;    // the new setup when accepted
  bool sync = false;   // sync field set (1 or 40–250 Hz)
};

// Checks and applies "S<acc1>,<acc2>,<acc3>,<acc4>,<sync>,<integ>,<avg>,<units>" (`fields` is the
// text after the S). Empty fields take the meter's defaults (adaptive integration, 1 average, no
// sync). The simulated meter has only the standard MS-75 lens (accessory 01) fitted: asking for
// any other accessory is the accessory error 50.
Pr650SetupResult ApplyPr650Setup(std::string_view fields);

}  // namespace brdf::sim
