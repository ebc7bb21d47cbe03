// The material file brdf-sim mounts (--material FILE, or `material` in its TOML file): read from
// disk and parsed by core/material/material_reader.h. docs/materials.md describes the format.
#pragma once

#include <string>

#include "core/material/material.h"
#include "core/status.h"
#include "tools/brdf-sim/optics/optics.h"

namespace brdf::sim {

// The material in the file at `path`, named by its `name` key or else by the file's stem.
// Errors: kNotFound when the file cannot be opened; kInvalidArgument naming every bad key with
// its line.
Result<material::Material> LoadMaterialFile(const std::string& path);

// Fills config.material from config.material_path (nothing to do without a path).
Status LoadMountedMaterial(OpticsConfig& config);

}  // namespace brdf::sim
