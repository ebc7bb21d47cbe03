// The rig's lamp: a tungsten-halogen source, modelled as a Planck radiator at its colour
// temperature (CIE illuminant A is 2856 K), scaled to the spectral irradiance it puts on the
// sample at normal incidence. What the lamp does to a surface (cos θi, the BRDF) is the optical
// model's business (optics/optics.h); this file only knows the lamp's spectrum.
#pragma once

#include <vector>

#include "core/wavelength_grid.h"

namespace brdf::sim {

struct LampConfig {
  double color_temperature_k = 2856;
  // Spectral irradiance on a surface facing the lamp, at 560 nm (W·m⁻²·nm⁻¹). 0.25 is what a
  // 1 kW quartz-halogen lamp gives at about half a metre: the white standard then reads some
  // 0.08 W·m⁻²·sr⁻¹·nm⁻¹ at 560 nm, a few thousand cd/m².
  double irradiance_at_560nm = 0.25;
};

class Lamp {
 public:
  explicit Lamp(LampConfig config = {});

  // Spectral irradiance E(λ) at normal incidence, W·m⁻²·nm⁻¹.
  double Irradiance(double wavelength_nm) const;
  std::vector<double> Spectrum(const WavelengthGrid& grid) const;

  const LampConfig& config() const { return config_; }

 private:
  // Planck's law up to a constant factor: λ⁻⁵ / (exp(c2 / (λT)) − 1), λ in nm.
  double PlanckShape(double wavelength_nm) const;

  LampConfig config_;
  double scale_ = 0;  // turns PlanckShape into irradiance
};

}  // namespace brdf::sim
