// The directional albedo of a material: of the light arriving from ωi, the fraction it reflects
// into the whole hemisphere, a(ωi, λ) = ∫ f(ωi, ωo, λ) cos θo dωo. Energy is conserved when
// a ≤ 1 for every ωi and λ. Computed by the midpoint rule over θo and φo on a regular grid
// (`step_deg` apart; 0.5° resolves a lobe a few degrees wide to well under 0.1 %). Pure; the cost
// is (90 / step) · (360 / step) evaluations of the material.
#pragma once

#include <vector>

#include "core/material/material.h"
#include "core/wavelength_grid.h"

namespace brdf::material {

std::vector<double> DirectionalAlbedo(const Material& material, double theta_i_deg,
                                      double phi_i_deg, const WavelengthGrid& grid,
                                      double step_deg = 0.5);

}  // namespace brdf::material
