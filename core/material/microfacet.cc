#include "core/material/microfacet.h"

#include <cmath>
#include <numbers>

namespace brdf::material {

double FacetDensity(FacetSlopes slopes, const Roughness& alpha, const Vec3& h) {
  if (h.z <= 0.0) return 0.0;
  const double sx = h.x / alpha.x, sy = h.y / alpha.y;
  const double z2 = h.z * h.z;
  const double norm = std::numbers::pi * alpha.x * alpha.y;
  if (slopes == FacetSlopes::kGgx) {
    const double q = sx * sx + sy * sy + z2;
    return 1.0 / (norm * q * q);
  }
  return std::exp(-(sx * sx + sy * sy) / z2) / (norm * z2 * z2);
}

double SmithLambda(FacetSlopes slopes, const Roughness& alpha, const Vec3& w) {
  if (w.z <= 0.0) return HUGE_VAL;
  // a⁻² = (αx² ωx² + αy² ωy²) / ωz²: the squared slope of the direction in units of roughness.
  const double px = alpha.x * w.x, py = alpha.y * w.y;
  const double inv_a2 = (px * px + py * py) / (w.z * w.z);
  if (inv_a2 == 0.0) return 0.0;
  if (slopes == FacetSlopes::kGgx) return (-1.0 + std::sqrt(1.0 + inv_a2)) / 2.0;
  const double a = 1.0 / std::sqrt(inv_a2);
  return (std::erf(a) - 1.0) / 2.0 + std::exp(-a * a) / (2.0 * a * std::sqrt(std::numbers::pi));
}

double SmithShadowing(FacetSlopes slopes, const Roughness& alpha, const DirectionPair& d) {
  const double sum = SmithLambda(slopes, alpha, d.wi) + SmithLambda(slopes, alpha, d.wo);
  return std::isfinite(sum) ? 1.0 / (1.0 + sum) : 0.0;
}

}  // namespace brdf::material
