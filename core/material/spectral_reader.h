// Reading one spectral parameter of a material file (spectral_value.h) from its TOML key:
//   albedo = 0.5                                    a constant
//   albedo = [[400, 0.2], [550, 0.5], [700, 0.6]]  (nm, value) points, nm increasing
//   albedo = { base = 0.25, amplitude = 0.45, center_nm = 610, width_nm = 90 }
// Problems go to the file's toml_keys::Problems with the key's line. Pure.
#pragma once

#include <string_view>

#include "core/material/spectral_value.h"
#include "core/toml/table_reader.h"

namespace brdf::material {

// The range every value of a spectral parameter must lie in.
struct ValueRange {
  double lo = 0;
  double hi = 1;
};

// Reads `key` of `table` into `out`. True when present and valid; false when absent (`out`
// unchanged) or wrong (the problem noted).
bool ReadSpectral(toml_keys::TableReader& table, toml_keys::Problems& problems,
                  std::string_view key, ValueRange range, SpectralValue& out);

}  // namespace brdf::material
