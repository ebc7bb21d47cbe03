// A material file (TOML) into a Material: its name and its lobes, each lobe a [[lobe]] table
// with a `type` and that type's parameters; spectral parameters as a number, a table of
// [nm, value] pairs, or a bump {base, amplitude, center_nm, width_nm}. docs/materials.md
// describes every key; deploy/materials/ holds examples.
//
// Every problem is reported the way core/toml/table_reader.h reports them, one line each, then
// what to do:
//   material file gold.toml: line 7, column 13: lobe[0].roughness: 3 is outside (0, 2]
//   material file gold.toml: line 9, column 1: lobe[0].n: missing; fresnel = "conductor" needs …
// Pure: the caller reads the file.
#pragma once

#include <string>
#include <string_view>

#include "core/material/material.h"
#include "core/status.h"

namespace brdf::material {

// Parses `toml_text` (from `source`, the file's name in every message). The material is named
// by the file's `name`, or `default_name` without one. Errors: kInvalidArgument naming every
// bad key with its line.
Result<Material> ReadMaterial(std::string_view toml_text, const std::string& source,
                              const std::string& default_name);

}  // namespace brdf::material
