// brdf-sim's settings of the rig's known errors (optics/errors.h): the [optics.errors] table of its
// TOML file and the flags that override it, and their checks. sim_config.h calls these; the
// README's tables and docs/simulator-errors.md list the keys and flags.
#pragma once

#include "core/status.h"
#include "core/toml/table_reader.h"
#include "tools/brdf-sim/optics/errors.h"

namespace CLI {
class App;
}

namespace brdf::sim {

// Reads the keys of [optics.errors] (`errors` is that table's reader) and finishes the table.
void ReadErrorSources(toml_keys::TableReader& errors, ErrorSources& out);

// Registers --gain-noise, --lamp-drift, --lamp-wander, --white-error, --pose-jitter,
// --wavelength-shift, --wavelength-shift-sigma and --stray-light, bound to `out`.
void AddErrorFlags(CLI::App& app, ErrorSources& out);

// Each value finite and in its range (σ ≥ 0, fractions below their physical limits); the
// message names the key and the flag.
Status ValidateErrorSources(const ErrorSources& e);

}  // namespace brdf::sim
