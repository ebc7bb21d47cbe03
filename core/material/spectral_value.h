// A spectral quantity of a material — an albedo, a Fresnel F0, a conductor's n or k, a lobe's
// weight — as a function of wavelength, in one of three forms:
//   a constant;
//   a table of (nm, value) points joined by straight lines, held at the end values beyond the
//   first and the last point;
//   a bump over a base, base + amplitude · exp(−((λ − center) / width)²) (the form of the
//   simulator's built-in paint, core/analytic_brdf.h).
// docs/materials.md shows how a material file writes each form. Pure.
#pragma once

#include <utility>
#include <vector>

namespace brdf::material {

class SpectralValue {
 public:
  // A constant 0.
  SpectralValue() = default;

  static SpectralValue Constant(double value);
  // `points` as (nm, value), with nm strictly increasing and at least one point (the material
  // reader checks both; a table that breaks them is treated as the constant 0).
  static SpectralValue Table(std::vector<std::pair<double, double>> points);
  static SpectralValue Bump(double base, double amplitude, double center_nm, double width_nm);

  // The value at `nm` (any finite wavelength).
  double At(double nm) const;
  // The least and the greatest value over all wavelengths (a table's extreme points; a bump's
  // base and base + amplitude).
  double Min() const { return Range().first; }
  double Max() const { return Range().second; }
  bool constant() const { return kind_ == Kind::kConstant; }

 private:
  enum class Kind { kConstant, kTable, kBump };
  std::pair<double, double> Range() const;

  Kind kind_ = Kind::kConstant;
  double value_ = 0;  // the constant, or the bump's base
  double amplitude_ = 0, center_nm_ = 0, width_nm_ = 1;
  std::vector<std::pair<double, double>> points_;
};

}  // namespace brdf::material
