#include "core/analytic_brdf.h"

#include <algorithm>
#include <cmath>
#include <numbers>

namespace brdf {
namespace {

constexpr double kDegToRad = std::numbers::pi / 180.0;

// Unit vector in the sample frame for polar θ and azimuth φ (degrees): (sinθ cosφ, sinθ sinφ,
// cosθ), the local frame (t, b, n) of docs/geometry.md ("Frames").
struct Vec3 {
  double x, y, z;
};

Vec3 LocalVector(double theta_deg, double phi_deg) {
  const double t = theta_deg * kDegToRad;
  const double p = phi_deg * kDegToRad;
  const double s = std::sin(t);
  return {s * std::cos(p), s * std::sin(p), std::cos(t)};
}

// A direction counts as above the surface for θ in [0°, 90°]; the grazing direction itself is kept
// (the diffuse term is not cosine-weighted, so it stays finite there).
bool AboveSurface(double theta_deg) {
  return theta_deg >= 0.0 && theta_deg <= 90.0;
}

bool Finite(const Directions& d) {
  return std::isfinite(d.theta_i) && std::isfinite(d.phi_i) && std::isfinite(d.theta_o) &&
         std::isfinite(d.phi_o);
}

}  // namespace

AnalyticBrdf AnalyticBrdf::PaintLike() {
  return AnalyticBrdf(AnalyticBrdfParams{});
}

AnalyticBrdf AnalyticBrdf::Glossy() {
  AnalyticBrdfParams p;
  p.specular_weight = 0.3;
  p.exponent_x = p.exponent_y = 200;
  return AnalyticBrdf(p);
}

AnalyticBrdf AnalyticBrdf::Brushed() {
  AnalyticBrdfParams p;
  // Brushing leaves fine grooves along the bitangent: the highlight is wide across the grooves
  // (tangent, low exponent) and narrow along them (bitangent, high exponent).
  p.exponent_x = 20;
  p.exponent_y = 200;
  return AnalyticBrdf(p);
}

// Diffuse part: albedo(λ)/π.
static double DiffuseBrdf(const AnalyticBrdfParams& p, double wavelength_nm) {
  const double u = (wavelength_nm - p.diffuse_peak_nm) / p.diffuse_width_nm;
  return (p.diffuse_base + p.diffuse_amp * std::exp(-u * u)) / std::numbers::pi;
}

// Glossy part, spectrally flat. Blinn-Phong on the half vector h with the "modified" energy
// normalisation (e+8)/(8π); the anisotropic form follows Ashikhmin-Shirley: the exponent is
// interpolated by the azimuth of h, e(h) = (ex·hx² + ey·hy²)/(hx² + hy²), and the normalisation is
// sqrt((ex+8)(ey+8))/(8π). Unlike Ashikhmin-Shirley we leave out the 1/(h·k · max(cosθi, cosθo))
// factor and the Fresnel term: they make the value diverge at grazing angles, and the virtual
// sample must stay finite everywhere. The lobe depends on wi + wo only, so it is exactly
// reciprocal.
static double SpecularBrdf(const AnalyticBrdfParams& p, const Directions& d) {
  if (p.specular_weight == 0.0) return 0.0;
  const Vec3 wi = LocalVector(d.theta_i, d.phi_i);
  const Vec3 wo = LocalVector(d.theta_o, d.phi_o);
  const Vec3 s{wi.x + wo.x, wi.y + wo.y, wi.z + wo.z};
  const double len2 = s.x * s.x + s.y * s.y + s.z * s.z;
  // Both directions grazing and opposite: no half vector, and no highlight either.
  if (len2 < 1e-24) return 0.0;
  const double inv = 1.0 / std::sqrt(len2);
  const double hx = s.x * inv, hy = s.y * inv, hz = std::clamp(s.z * inv, 0.0, 1.0);
  const double tangential2 = hx * hx + hy * hy;
  const bool anisotropic = p.exponent_x != p.exponent_y;
  double exponent = p.exponent_x;
  // At h = n (tangential2 = 0) the azimuth of h is undefined but hz^e = 1 for any e.
  if (anisotropic && tangential2 > 0.0) {
    exponent = (p.exponent_x * hx * hx + p.exponent_y * hy * hy) / tangential2;
  }
  const double norm =
      anisotropic ? std::sqrt((p.exponent_x + 8.0) * (p.exponent_y + 8.0)) : p.exponent_x + 8.0;
  return p.specular_weight * norm / (8.0 * std::numbers::pi) * std::pow(hz, exponent);
}

double AnalyticBrdf::Evaluate(const Directions& d, double wavelength_nm) const {
  if (!Finite(d) || !std::isfinite(wavelength_nm)) return 0.0;
  if (!AboveSurface(d.theta_i) || !AboveSurface(d.theta_o)) return 0.0;
  return DiffuseBrdf(p_, wavelength_nm) + SpecularBrdf(p_, d);
}

void AnalyticBrdf::EvaluateSpectrum(const Directions& d, const WavelengthGrid& grid,
                                    std::span<double> out) const {
  const std::size_t n = std::min(out.size(), grid.count);
  if (!Finite(d) || !AboveSurface(d.theta_i) || !AboveSurface(d.theta_o)) {
    std::fill(out.begin(), out.begin() + static_cast<std::ptrdiff_t>(n), 0.0);
    return;
  }
  // The glossy lobe is spectrally flat: compute it once for the whole spectrum.
  const double specular = SpecularBrdf(p_, d);
  for (std::size_t k = 0; k < n; ++k) out[k] = DiffuseBrdf(p_, grid.at(k)) + specular;
}

std::vector<double> AnalyticBrdf::EvaluateSpectrum(const Directions& d,
                                                   const WavelengthGrid& grid) const {
  std::vector<double> out(grid.count);
  EvaluateSpectrum(d, grid, out);
  return out;
}

}  // namespace brdf
