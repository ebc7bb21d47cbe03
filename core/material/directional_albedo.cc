#include "core/material/directional_albedo.h"

#include <cmath>
#include <numbers>

namespace brdf::material {

std::vector<double> DirectionalAlbedo(const Material& material, double theta_i_deg,
                                      double phi_i_deg, const WavelengthGrid& grid,
                                      double step_deg) {
  constexpr double kDegToRad = std::numbers::pi / 180.0;
  std::vector<double> nm(grid.count), f(grid.count), albedo(grid.count, 0.0);
  for (std::size_t k = 0; k < grid.count; ++k) nm[k] = grid.at(k);
  const int polar = static_cast<int>(std::ceil(90.0 / step_deg));
  const int azimuthal = static_cast<int>(std::ceil(360.0 / step_deg));
  const double d_theta = 90.0 / polar * kDegToRad, d_phi = 360.0 / azimuthal * kDegToRad;
  const Vec3 wi = LocalVector(theta_i_deg, phi_i_deg);
  for (int a = 0; a < polar; ++a) {
    const double theta = (a + 0.5) * d_theta;
    // dω cos θo = sin θo cos θo dθ dφ.
    const double weight = std::sin(theta) * std::cos(theta) * d_theta * d_phi;
    for (int b = 0; b < azimuthal; ++b) {
      const double phi = -std::numbers::pi + (b + 0.5) * d_phi;
      const Vec3 wo{std::sin(theta) * std::cos(phi), std::sin(theta) * std::sin(phi),
                    std::cos(theta)};
      material.Evaluate(DirectionPair{wi, wo}, nm, f);
      for (std::size_t k = 0; k < grid.count; ++k) albedo[k] += f[k] * weight;
    }
  }
  return albedo;
}

}  // namespace brdf::material
