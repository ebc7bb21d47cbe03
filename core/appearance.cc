#include "core/appearance.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <numbers>

#include "core/geometry.h"

namespace brdf {
namespace {

constexpr double kDeg = 180.0 / std::numbers::pi;

// XYZ of a unit value in each band (ReflectanceToXyz is linear in the reflectance): the colour of
// any spectrum on `grid` is Σ value_b · weights[b], exactly what ReflectanceToXyz gives.
Result<std::vector<Xyz>> BandWeights(const WavelengthGrid& grid, const Spectrum& illuminant,
                                     const ColorMatchingFunctions& cmf) {
  if (!grid.valid()) return InvalidArgument("appearance: the wavelength grid is invalid");
  std::vector<Xyz> w;
  w.reserve(grid.count);
  Spectrum impulse{grid, std::vector<double>(grid.count, 0.0)};
  for (std::size_t b = 0; b < grid.count; ++b) {
    impulse.values[b] = 1.0;
    Result<Xyz> xyz = ReflectanceToXyz(impulse, illuminant, cmf);
    if (!xyz.ok()) return xyz.status().WithContext("appearance");
    w.push_back(*xyz);
    impulse.values[b] = 0.0;
  }
  return w;
}

Xyz Apply(const std::vector<Xyz>& weights, std::span<const double> values, double scale) {
  Xyz out;
  for (std::size_t b = 0; b < weights.size() && b < values.size(); ++b) {
    out.X += values[b] * weights[b].X;
    out.Y += values[b] * weights[b].Y;
    out.Z += values[b] * weights[b].Z;
  }
  out.X *= scale;
  out.Y *= scale;
  out.Z *= scale;
  return out;
}

std::uint8_t To8Bit(double linear) {
  return static_cast<std::uint8_t>(std::lround(EncodeSrgbComponent(linear) * 255.0));
}

std::array<std::uint8_t, 3> To8Bit(const Rgb& linear) {
  return {To8Bit(linear.r), To8Bit(linear.g), To8Bit(linear.b)};
}

double Dot(const std::array<double, 3>& a, const std::array<double, 3>& b) {
  return a[0] * b[0] + a[1] * b[1] + a[2] * b[2];
}

// The isotropic direction of light `l` and view `v` (unit) at a point of normal `n` (unit):
// θ from n, φ the angle between their projections on the tangent plane (0 where either lies
// along n).
IsoDirection LocalDirection(const std::array<double, 3>& n, const std::array<double, 3>& l,
                            const std::array<double, 3>& v) {
  const double cl = std::clamp(Dot(n, l), -1.0, 1.0);
  const double cv = std::clamp(Dot(n, v), -1.0, 1.0);
  IsoDirection d{std::acos(cl) * kDeg, std::acos(cv) * kDeg, 0};
  const std::array<double, 3> lt{l[0] - cl * n[0], l[1] - cl * n[1], l[2] - cl * n[2]};
  const std::array<double, 3> vt{v[0] - cv * n[0], v[1] - cv * n[1], v[2] - cv * n[2]};
  const double ll = std::sqrt(Dot(lt, lt));
  const double lv = std::sqrt(Dot(vt, vt));
  if (ll > 1e-12 && lv > 1e-12) {
    d.phi = std::acos(std::clamp(Dot(lt, vt) / (ll * lv), -1.0, 1.0)) * kDeg;
  }
  if (d.theta_i < kNormalThetaEpsilonDeg || d.theta_o < kNormalThetaEpsilonDeg) d.phi = 0;
  return d;
}

}  // namespace

Spectrum CieIlluminantA(const WavelengthGrid& grid) {
  constexpr double c2 = 1.435e7;  // nm·K, CIE 15's value for illuminant A
  constexpr double t = 2848;      // K: with c2 = 1.4350e7 this is 2856 K on the ITS-68 scale
  Spectrum s{grid, std::vector<double>(grid.count)};
  for (std::size_t i = 0; i < grid.count; ++i) {
    const double l = grid.at(i);
    s.values[i] =
        100.0 * std::pow(560.0 / l, 5) * std::expm1(c2 / (t * 560.0)) / std::expm1(c2 / (t * l));
  }
  return s;
}

std::string HexColour(const std::array<std::uint8_t, 3>& rgb) {
  char text[8];
  std::snprintf(text, sizeof text, "#%02x%02x%02x", rgb[0], rgb[1], rgb[2]);
  return text;
}

Result<SampleColour> ComputeSampleColour(const BrdfLookup& brdf, const WavelengthGrid& grid,
                                         const Spectrum& illuminant,
                                         const ColorMatchingFunctions& cmf) {
  if (!grid.valid()) return InvalidArgument("sample colour: the wavelength grid is invalid");
  SampleColour c;
  c.reflectance = {grid, std::vector<double>(grid.count, 0.0)};
  if (!brdf(kColourGeometry, c.reflectance.values)) {
    return FailedPrecondition(
        "sample colour: the BRDF has no value at the 45°:0° geometry (θi = 45°, θo = 0°); "
        "measure near it or use the fill chain");
  }
  for (double& v : c.reflectance.values) v *= std::numbers::pi;
  Result<Xyz> xyz = ReflectanceToXyz(c.reflectance, illuminant, cmf);
  if (!xyz.ok()) return xyz.status().WithContext("sample colour");
  c.xyz = *xyz;
  if (Result<Chromaticity> xy = ToChromaticity(c.xyz); xy.ok()) c.xy = *xy;
  c.linear_srgb = XyzToLinearSrgb(c.xyz);
  c.srgb8 = To8Bit(c.linear_srgb);
  c.hex = HexColour(c.srgb8);
  return c;
}

Result<LitSphere> RenderLitSphere(const BrdfLookup& brdf, const WavelengthGrid& grid,
                                  const Spectrum& illuminant, const ColorMatchingFunctions& cmf,
                                  const SphereOptions& options) {
  if (options.size < 1 || options.size > kMaxSphereSize) {
    return InvalidArgument("lit sphere: size " + std::to_string(options.size) +
                           " pixels; give 1 to " + std::to_string(kMaxSphereSize));
  }
  std::array<double, 3> light = options.light;
  const double length = std::sqrt(Dot(light, light));
  if (!std::isfinite(length) || length <= 0) {
    return InvalidArgument("lit sphere: the light direction must be a finite, non-zero vector");
  }
  for (double& v : light) v /= length;
  Result<std::vector<Xyz>> weights = BandWeights(grid, illuminant, cmf);
  if (!weights.ok()) return weights.status().WithContext("lit sphere");

  const int n = options.size;
  LitSphere s;
  s.size = n;
  s.rgba.assign(static_cast<std::size_t>(n) * static_cast<std::size_t>(n) * 4, 0);
  const std::array<double, 3> view{0, 0, 1};
  std::vector<double> f(grid.count);
  for (int row = 0; row < n; ++row) {
    const double y = 1.0 - 2.0 * (row + 0.5) / n;
    for (int col = 0; col < n; ++col) {
      const double x = 2.0 * (col + 0.5) / n - 1.0;
      const double r2 = x * x + y * y;
      if (r2 >= 1.0) continue;  // transparent
      std::uint8_t* px = &s.rgba[(static_cast<std::size_t>(row) * n + col) * 4];
      px[3] = 255;
      ++s.disc_pixels;
      const std::array<double, 3> normal{x, y, std::sqrt(1.0 - r2)};
      const double cos_i = Dot(normal, light);
      if (cos_i <= 0) {
        ++s.unlit_pixels;
        continue;
      }
      if (!brdf(LocalDirection(normal, light, view), f)) {
        ++s.missing_pixels;
        continue;
      }
      // π f_r cos θi: a white Lambertian lit head-on is the perfect white (Y = 1).
      const Xyz xyz = Apply(*weights, f, std::numbers::pi * cos_i);
      s.peak_y = std::max(s.peak_y, xyz.Y);
      const std::array<std::uint8_t, 3> rgb = To8Bit(XyzToLinearSrgb(xyz));
      std::copy(rgb.begin(), rgb.end(), px);
    }
  }
  return s;
}

}  // namespace brdf
