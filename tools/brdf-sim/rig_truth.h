// `brdf-sim truth`: the virtual sample's true BRDF at one direction, as text a person or a test
// reads. Two columns ("380 0.1234") by default, or one JSON object with --json.
#pragma once

#include <string>

#include "tools/brdf-sim/sim_config.h"

namespace brdf::sim {

// The true BRDF (sr⁻¹) at 380–780 nm every 4 nm for the query's directions.
// Text: a comment line naming the directions, then "<nm> <value>" per band.
// JSON: {"theta_i":…, "phi_i":…, "theta_o":…, "phi_o":…, "anisotropic":…, "unit":"sr^-1",
//        "wavelength_nm":[…], "brdf":[…]}. Values print with 17 significant digits (round-trip).
std::string FormatTruth(const TruthQuery& query);

// Checks the query's angles are finite; the message names the flag.
Status ValidateTruthQuery(const TruthQuery& query);

}  // namespace brdf::sim
