// The CSV files of brdf-interp, parsed from text already in memory (the tool reads the files), so
// the parser is pure and can be fuzzed. Every error names the source, the line (1-based) and the
// column (1-based, with its header name) and says what was expected.
//
// Samples:  theta_i,theta_o,phi,380,384,…            (isotropic, 3 coordinates)
//       or  theta_i,phi_i,theta_o,phi_o,380,384,…    (anisotropic, 4 coordinates)
//           then one row per sample: coordinates in degrees, one value per wavelength column
//           (the header is the wavelength in nm: "380", "380.5" or "380nm"; increasing).
// Queries:  the coordinate columns only, same names.
// Fields are separated by commas and may be surrounded by spaces or double quotes; lines end in
// LF or CRLF; blank lines are skipped; a UTF-8 byte-order mark is ignored. Every value must be a
// finite number (no NaN, no inf, no empty field).
#pragma once

#include <cstddef>
#include <memory>
#include <span>
#include <string>
#include <string_view>
#include <vector>

#include "core/interp/interpolator.h"
#include "core/status.h"

namespace brdf::interp {

// A header line and rows of finite numbers.
struct CsvTable {
  std::vector<std::string> header;  // column names, trimmed, unquoted
  std::size_t header_line = 0;      // the 1-based line number of the header
  std::vector<double> values;       // rows() × columns(), row-major
  std::vector<std::size_t> lines;   // the 1-based line number of each data row

  std::size_t columns() const { return header.size(); }
  std::size_t rows() const { return lines.size(); }
  double at(std::size_t row, std::size_t column) const { return values[row * columns() + column]; }
};

// Errors (kInvalidArgument): an empty text (no header), an empty or duplicate column name, a row
// with more or fewer fields than the header, a field that is empty, not a number, NaN or infinite,
// an unterminated quote. Zero data rows is not an error here.
Result<CsvTable> ParseNumericCsv(std::string_view text, std::string_view source);

// The coordinate columns' names: {"theta_i", "theta_o", "phi"} or
// {"theta_i", "phi_i", "theta_o", "phi_o"}.
std::span<const char* const> CoordinateColumns(int dims);

struct SampleTable {
  int dims = 3;
  std::vector<std::string> wavelength_headers;  // as written in the file
  std::vector<double> wavelengths_nm;
  std::shared_ptr<SampleSet> samples;  // sample id = 0-based data row
};

// Errors: everything ParseNumericCsv rejects, missing or misnamed coordinate columns, no
// wavelength column, a wavelength header that is not a positive number or not increasing, no
// data rows.
Result<SampleTable> ParseSamplesCsv(std::string_view text, std::string_view source);

struct QueryTable {
  int dims = 3;
  std::vector<double> coords;      // size() × dims
  std::vector<std::size_t> lines;  // the 1-based line number of each query

  std::size_t size() const { return lines.size(); }
  std::span<const double> query(std::size_t i) const {
    return {coords.data() + i * static_cast<std::size_t>(dims), static_cast<std::size_t>(dims)};
  }
};

// Errors: everything ParseNumericCsv rejects, a header other than the coordinate columns.
// Zero queries is allowed.
Result<QueryTable> ParseQueriesCsv(std::string_view text, std::string_view source);

}  // namespace brdf::interp
