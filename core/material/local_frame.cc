#include "core/material/local_frame.h"

#include <cmath>
#include <numbers>

namespace brdf::material {

Vec3 LocalVector(double theta_deg, double phi_deg) {
  // Written as core/analytic_brdf.cc writes it, so that the built-in samples agree to the bit.
  constexpr double kDegToRad = std::numbers::pi / 180.0;
  const double t = theta_deg * kDegToRad;
  const double p = phi_deg * kDegToRad;
  const double s = std::sin(t);
  return {s * std::cos(p), s * std::sin(p), std::cos(t)};
}

DirectionPair ToVectors(const Directions& d) {
  return {LocalVector(d.theta_i, d.phi_i), LocalVector(d.theta_o, d.phi_o)};
}

bool HalfVector(const DirectionPair& d, Vec3& h) {
  const Vec3 s{d.wi.x + d.wo.x, d.wi.y + d.wo.y, d.wi.z + d.wo.z};
  const double len2 = s.x * s.x + s.y * s.y + s.z * s.z;
  if (len2 < 1e-24) return false;
  const double inv = 1.0 / std::sqrt(len2);
  h = {s.x * inv, s.y * inv, s.z * inv};
  return true;
}

}  // namespace brdf::material
