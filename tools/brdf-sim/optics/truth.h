// `brdf-sim truth`: the virtual sample's true BRDF at one direction, as text a person or a test
// reads. Two columns ("380 0.1234") by default, or one JSON object with --json. The sample is
// the one a run with the same flags and --config mounts (--material, --glossy, --anisotropic),
// so the values are exactly those the simulated meter's readings are drawn from, in the same
// sample frame (docs/geometry.md).
#pragma once

#include <string>

#include "core/material/material.h"
#include "tools/brdf-sim/sim_config.h"

namespace brdf::sim {

// The true BRDF (sr⁻¹) of `sample` on `grid` (the meter's: 380–780 nm every 4 nm for the PR-650,
// 2 nm for a PR-670, 1 nm for a CS-2000) for the query's directions.
// Text: a comment line naming the sample and the directions, then "<nm> <value>" per band.
// JSON: {"theta_i":…, "phi_i":…, "theta_o":…, "phi_o":…, "anisotropic":…, "sample":"<name>",
//        "unit":"sr^-1", "wavelength_nm":[…], "brdf":[…]}. Values print with 17 significant
// digits (round-trip).
std::string FormatTruth(const TruthQuery& query, const material::Material& sample,
                        const WavelengthGrid& grid = WavelengthGrid::Pr650());
// The same for the built-in sample the query's --anisotropic or --glossy names.
std::string FormatTruth(const TruthQuery& query);

// Checks the query's angles are finite and that it names one sample; the message names the flag.
Status ValidateTruthQuery(const TruthQuery& query);

// The sample `brdf-sim [run flags] truth [query flags]` evaluates: the query's --material,
// --anisotropic or --glossy, else the run's (flags given before `truth`, or --config's). Checks
// the query too; errors name the flag, or the material file's bad keys.
Result<material::Material> TruthSample(const TruthQuery& query, const OpticsConfig& run);

}  // namespace brdf::sim
