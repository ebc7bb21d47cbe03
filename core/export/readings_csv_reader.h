// A readings CSV (readings_csv.h) read back: the quantity, the wavelength grid, and each row's id,
// directions, values and, when the file has u_<λ> columns, uncertainties. For brdf-export's fit
// from a file the daemon exported (Data.Export READINGS_CSV). Columns are found by their header
// names, so files of every layout brdfd has written read alike: with or without
// integration_note, with or without the u_<λ> columns. Parsed from text in memory (the tool reads
// the file): pure.
#pragma once

#include <cstdint>
#include <string>
#include <string_view>
#include <vector>

#include "core/pose.h"
#include "core/status.h"
#include "core/wavelength_grid.h"

namespace brdf::exports {

struct ReadingsCsvRow {
  std::int64_t id = 0;
  std::string kind;  // "sample", "reference", "dark"
  Directions directions;
  std::vector<double> values;  // one per band
  // One per band when the row carries them (every u field a number); empty when the file has no
  // u columns or the row's are empty (not estimated).
  std::vector<double> u;
};

struct ReadingsCsv {
  std::int64_t session_id = -1;  // from the '# brdfd readings export: session N "name"' line
  std::string session_name;
  std::string quantity;  // from '# quantity: NAME in …' ("radiance", "reflectance", "brdf"), or ""
  WavelengthGrid grid;   // from the numeric column headers (regularly spaced)
  bool has_u_columns = false;
  std::vector<ReadingsCsvRow> rows;
};

// Errors (kInvalidArgument, naming `source`, the line and what to do): no header row, a missing
// id/theta_i_deg/phi_i_deg/theta_o_deg/phi_o_deg column, no spectral columns or irregularly
// spaced ones, u_<λ> columns that do not match the spectral ones, a row with another number of
// fields than the header, a value that is not a number.
Result<ReadingsCsv> ParseReadingsCsv(std::string_view text, std::string_view source);

}  // namespace brdf::exports
