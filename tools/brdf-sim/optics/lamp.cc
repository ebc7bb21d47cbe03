#include "tools/brdf-sim/optics/lamp.h"

#include <cmath>

namespace brdf::sim {
namespace {
// Second radiation constant c2 = h·c/k, in nm·K.
constexpr double kC2NmK = 1.4387768775039337e7;
}  // namespace

Lamp::Lamp(LampConfig config) : config_(config) {
  const double at_560 = PlanckShape(560.0);
  scale_ = at_560 > 0 ? config_.irradiance_at_560nm / at_560 : 0.0;
}

double Lamp::PlanckShape(double wavelength_nm) const {
  if (!(wavelength_nm > 0) || !(config_.color_temperature_k > 0)) return 0.0;
  // Relative to 560 nm so the numbers stay near 1 whatever the temperature.
  const double rel = wavelength_nm / 560.0;
  const double x = kC2NmK / (wavelength_nm * config_.color_temperature_k);
  return 1.0 / (rel * rel * rel * rel * rel * std::expm1(x));
}

double Lamp::Irradiance(double wavelength_nm) const {
  return scale_ * PlanckShape(wavelength_nm);
}

std::vector<double> Lamp::Spectrum(const WavelengthGrid& grid) const {
  std::vector<double> out(grid.count);
  for (std::size_t k = 0; k < grid.count; ++k) out[k] = Irradiance(grid.at(k));
  return out;
}

}  // namespace brdf::sim
