#include "core/fit/models.h"

#include <algorithm>
#include <cmath>
#include <numbers>

namespace brdf::fit {
namespace {

constexpr double kPi = std::numbers::pi;
constexpr double kDegToRad = kPi / 180.0;

// 2 / (c + √(α² + (1 − α²) c²)) = G1(ω) / cos θ: finite (2/α) at grazing incidence.
double G1OverCos(double c, double a2) {
  return 2.0 / (c + std::sqrt(a2 + (1.0 - a2) * c * c));
}

}  // namespace

double LambertBrdf(double albedo) {
  return albedo / kPi;
}

LobeGeometry LobeGeometryOf(const IsoDirection& at) {
  const double ti = at.theta_i * kDegToRad, to = at.theta_o * kDegToRad, ph = at.phi * kDegToRad;
  LobeGeometry g;
  g.cos_i = std::cos(ti);
  g.cos_o = std::cos(to);
  if (g.cos_i < 0 || g.cos_o < 0) return g;
  const double si = std::sin(ti), so = std::sin(to);
  // ωi = (si, 0, ci), ωo = (so cos φ, so sin φ, co); h = (ωi + ωo) / |ωi + ωo|.
  const double hx = si + so * std::cos(ph), hy = so * std::sin(ph), hz = g.cos_i + g.cos_o;
  const double len = std::sqrt(hx * hx + hy * hy + hz * hz);
  if (len < 1e-12) return g;  // both grazing and opposite: no half vector, no highlight
  g.cos_h = hz / len;
  g.cos_d = std::clamp((si * hx + g.cos_i * hz) / len, 0.0, 1.0);
  g.above = true;
  return g;
}

double CookTorranceSpecularAt(const LobeGeometry& g, double alpha, double f0) {
  if (!g.above) return 0.0;
  const double a2 = alpha * alpha;
  const double denom = g.cos_h * g.cos_h * (a2 - 1.0) + 1.0;
  const double d = a2 / (kPi * denom * denom);
  const double m = 1.0 - g.cos_d;
  const double m2 = m * m;
  const double fresnel = f0 + (1.0 - f0) * m2 * m2 * m;
  return d * fresnel * G1OverCos(g.cos_i, a2) * G1OverCos(g.cos_o, a2) / 4.0;
}

double CookTorranceSpecular(const IsoDirection& at, double alpha, double f0) {
  return CookTorranceSpecularAt(LobeGeometryOf(at), alpha, f0);
}

double CookTorranceBrdf(const IsoDirection& at, const CookTorranceParams& p) {
  return p.kd / kPi + p.ks * CookTorranceSpecular(at, p.alpha, p.f0);
}

void CookTorranceSpectrumAt(const LobeGeometry& g, std::span<const CookTorranceParams> band,
                            std::span<double> out) {
  const std::size_t n = std::min(out.size(), band.size());
  double specular = 0;
  for (std::size_t b = 0; b < n; ++b) {
    const CookTorranceParams& p = band[b];
    if (b == 0 || p.alpha != band[b - 1].alpha || p.f0 != band[b - 1].f0) {
      specular = CookTorranceSpecularAt(g, p.alpha, p.f0);
    }
    out[b] = p.kd / kPi + p.ks * specular;
  }
}

}  // namespace brdf::fit
