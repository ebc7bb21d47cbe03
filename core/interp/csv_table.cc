#include "core/interp/csv_table.h"

#include <array>
#include <charconv>
#include <cmath>
#include <set>
#include <system_error>

namespace brdf::interp {
namespace {

constexpr std::array<const char*, 3> kIsotropic = {"theta_i", "theta_o", "phi"};
constexpr std::array<const char*, 4> kAnisotropic = {"theta_i", "phi_i", "theta_o", "phi_o"};

std::string_view Trim(std::string_view s) {
  while (!s.empty() && (s.front() == ' ' || s.front() == '\t')) s.remove_prefix(1);
  while (!s.empty() && (s.back() == ' ' || s.back() == '\t')) s.remove_suffix(1);
  return s;
}

// At most this much of a bad field is quoted back in a message.
std::string Quote(std::string_view field) {
  constexpr std::size_t kMax = 40;
  std::string out = "'" + std::string(field.substr(0, kMax));
  if (field.size() > kMax) out += "…";
  return out + "'";
}

std::string Where(std::string_view source, std::size_t line) {
  return std::string(source) + ":" + std::to_string(line) + ": ";
}

std::string ColumnLabel(std::size_t column, const std::vector<std::string>& header) {
  std::string out = "column " + std::to_string(column + 1);
  if (column < header.size()) out += " (" + header[column] + ")";
  return out;
}

// Splits one line into fields: commas separate, spaces around a field are dropped, a field may
// be double-quoted ("" is a literal quote inside). `storage` keeps unquoted copies alive.
Status SplitFields(std::string_view line, std::string_view source, std::size_t line_number,
                   std::vector<std::string_view>& fields, std::vector<std::string>& storage) {
  fields.clear();
  storage.clear();
  storage.reserve(line.size() / 2 + 1);  // no reallocation: fields point into it
  std::size_t pos = 0;
  while (true) {
    while (pos < line.size() && (line[pos] == ' ' || line[pos] == '\t')) ++pos;
    if (pos < line.size() && line[pos] == '"') {
      std::string value;
      ++pos;
      bool closed = false;
      while (pos < line.size()) {
        if (line[pos] == '"') {
          if (pos + 1 < line.size() && line[pos + 1] == '"') {
            value += '"';
            pos += 2;
            continue;
          }
          closed = true;
          ++pos;
          break;
        }
        value += line[pos++];
      }
      if (!closed) {
        return InvalidArgument(Where(source, line_number) + "field " +
                               std::to_string(fields.size() + 1) +
                               " opens a double quote that is not closed on this line");
      }
      while (pos < line.size() && (line[pos] == ' ' || line[pos] == '\t')) ++pos;
      if (pos < line.size() && line[pos] != ',') {
        return InvalidArgument(Where(source, line_number) + "field " +
                               std::to_string(fields.size() + 1) +
                               " has text after its closing double quote");
      }
      storage.push_back(std::move(value));
      fields.push_back(Trim(storage.back()));
    } else {
      const std::size_t comma = line.find(',', pos);
      const std::size_t stop = comma == std::string_view::npos ? line.size() : comma;
      fields.push_back(Trim(line.substr(pos, stop - pos)));
      pos = stop;
    }
    if (pos >= line.size()) break;
    ++pos;  // the comma
    if (pos == line.size()) {
      fields.push_back({});  // a trailing comma leaves an empty last field
      break;
    }
  }
  return Status::Ok();
}

// A finite double from the whole field ("+" prefix allowed). On failure, what is wrong.
bool ParseNumber(std::string_view field, double& out, std::string& problem) {
  if (field.empty()) {
    problem = "is empty; every field needs a number";
    return false;
  }
  std::string_view digits = field;
  if (digits.front() == '+') digits.remove_prefix(1);
  const auto [end, ec] = std::from_chars(digits.data(), digits.data() + digits.size(), out);
  if (ec == std::errc::result_out_of_range) {
    problem = Quote(field) + " is out of the range of a double";
    return false;
  }
  if (ec != std::errc() || end != digits.data() + digits.size()) {
    problem = Quote(field) + " is not a number";
    return false;
  }
  if (!std::isfinite(out)) {
    problem = Quote(field) + " is not a finite number (NaN and infinity are not allowed)";
    return false;
  }
  return true;
}

std::string Joined(std::span<const char* const> names) {
  std::string out;
  for (const char* n : names) {
    if (!out.empty()) out += ",";
    out += n;
  }
  return out;
}

// Checks that the header starts with the coordinate columns for `dims`.
Status CheckCoordinateColumns(const CsvTable& table, int dims, std::string_view source,
                              std::size_t header_line, const std::string& usage) {
  const auto expected = CoordinateColumns(dims);
  for (std::size_t j = 0; j < expected.size(); ++j) {
    if (j >= table.header.size()) {
      return InvalidArgument(Where(source, header_line) + "missing column " +
                             std::to_string(j + 1) + " '" + expected[j] + "'; " + usage);
    }
    if (table.header[j] != expected[j]) {
      return InvalidArgument(Where(source, header_line) + "column " + std::to_string(j + 1) +
                             " is " + Quote(table.header[j]) + " where '" + expected[j] +
                             "' was expected; " + usage);
    }
  }
  return Status::Ok();
}

// Which layout the header announces: 4D when the second column is phi_i.
int DimsFromHeader(const CsvTable& table) {
  return table.header.size() >= 2 && table.header[1] == "phi_i" ? 4 : 3;
}

}  // namespace

std::span<const char* const> CoordinateColumns(int dims) {
  if (dims == 4) return kAnisotropic;
  return kIsotropic;
}

Result<CsvTable> ParseNumericCsv(std::string_view text, std::string_view source) {
  if (text.substr(0, 3) == "\xEF\xBB\xBF") text.remove_prefix(3);
  CsvTable table;
  std::vector<std::string_view> fields;
  std::vector<std::string> storage;
  bool have_header = false;
  std::size_t header_line = 0;
  std::size_t line_number = 0;
  std::size_t pos = 0;
  while (pos < text.size()) {
    const std::size_t newline = text.find('\n', pos);
    const std::size_t stop = newline == std::string_view::npos ? text.size() : newline;
    std::string_view line = text.substr(pos, stop - pos);
    pos = stop + 1;
    ++line_number;
    if (!line.empty() && line.back() == '\r') line.remove_suffix(1);
    if (Trim(line).empty()) continue;
    BRDF_RETURN_IF_ERROR(SplitFields(line, source, line_number, fields, storage));

    if (!have_header) {
      have_header = true;
      header_line = line_number;
      table.header_line = line_number;
      std::set<std::string_view> seen;
      for (std::size_t j = 0; j < fields.size(); ++j) {
        if (fields[j].empty()) {
          return InvalidArgument(Where(source, line_number) + "column " + std::to_string(j + 1) +
                                 " of the header has no name");
        }
        if (!seen.insert(fields[j]).second) {
          return InvalidArgument(Where(source, line_number) + "column " + std::to_string(j + 1) +
                                 " repeats the name " + Quote(fields[j]));
        }
        table.header.emplace_back(fields[j]);
      }
      continue;
    }
    if (fields.size() != table.header.size()) {
      return InvalidArgument(
          Where(source, line_number) + "this row has " + std::to_string(fields.size()) +
          " fields; the header (line " + std::to_string(header_line) + ") has " +
          std::to_string(table.header.size()) + ": every row needs one value per column");
    }
    for (std::size_t j = 0; j < fields.size(); ++j) {
      double value = 0;
      std::string problem;
      if (!ParseNumber(fields[j], value, problem)) {
        return InvalidArgument(Where(source, line_number) + ColumnLabel(j, table.header) + " " +
                               problem);
      }
      table.values.push_back(value);
    }
    table.lines.push_back(line_number);
  }
  if (!have_header) {
    return InvalidArgument(std::string(source) +
                           ": the file is empty; expected a header line (e.g. "
                           "theta_i,theta_o,phi,380,384,…) and data rows");
  }
  return table;
}

Result<SampleTable> ParseSamplesCsv(std::string_view text, std::string_view source) {
  BRDF_ASSIGN_OR_RETURN(const CsvTable table, ParseNumericCsv(text, source));
  const std::size_t header_line = table.header_line;
  const int dims = DimsFromHeader(table);
  const std::string usage = "a samples file starts with the columns " +
                            Joined(CoordinateColumns(3)) + " (or " + Joined(CoordinateColumns(4)) +
                            "), then one column per wavelength named by its value in nm";
  BRDF_RETURN_IF_ERROR(CheckCoordinateColumns(table, dims, source, header_line, usage));
  const auto d = static_cast<std::size_t>(dims);
  if (table.columns() == d) {
    return InvalidArgument(Where(source, header_line) +
                           "no wavelength columns after the coordinates; " + usage);
  }
  SampleTable out;
  out.dims = dims;
  for (std::size_t j = d; j < table.columns(); ++j) {
    std::string_view name = table.header[j];
    if (name.size() > 2 && name.substr(name.size() - 2) == "nm") name.remove_suffix(2);
    double nm = 0;
    std::string problem;
    if (!ParseNumber(Trim(name), nm, problem) || !(nm > 0)) {
      return InvalidArgument(Where(source, header_line) + "column " + std::to_string(j + 1) +
                             " is named " + Quote(table.header[j]) +
                             "; a spectral column's name is its wavelength in nm (e.g. 380)");
    }
    if (!out.wavelengths_nm.empty() && !(nm > out.wavelengths_nm.back())) {
      return InvalidArgument(Where(source, header_line) + "column " + std::to_string(j + 1) + " (" +
                             table.header[j] +
                             " nm) does not come after the previous "
                             "wavelength; list the wavelengths in increasing order");
    }
    out.wavelengths_nm.push_back(nm);
    out.wavelength_headers.push_back(table.header[j]);
  }
  if (table.rows() == 0) {
    return InvalidArgument(std::string(source) +
                           ": the header has no data rows after it; "
                           "a samples file needs at least one sample");
  }
  const int bands = static_cast<int>(table.columns() - d);
  out.samples = std::make_shared<SampleSet>(dims, bands);
  for (std::size_t r = 0; r < table.rows(); ++r) {
    const std::span<const double> row(table.values.data() + r * table.columns(), table.columns());
    const Status s =
        out.samples->Add(static_cast<std::int64_t>(r), row.subspan(0, d), row.subspan(d));
    if (!s.ok()) return s.WithContext(Where(source, table.lines[r]));
  }
  return out;
}

Result<QueryTable> ParseQueriesCsv(std::string_view text, std::string_view source) {
  BRDF_ASSIGN_OR_RETURN(CsvTable table, ParseNumericCsv(text, source));
  const int dims = DimsFromHeader(table);
  const std::string usage = "a queries file has exactly the columns " +
                            Joined(CoordinateColumns(3)) + " (or " + Joined(CoordinateColumns(4)) +
                            ")";
  const std::size_t line = table.header_line;
  BRDF_RETURN_IF_ERROR(CheckCoordinateColumns(table, dims, source, line, usage));
  if (table.columns() > static_cast<std::size_t>(dims)) {
    return InvalidArgument(Where(source, line) + "unexpected column " + std::to_string(dims + 1) +
                           " " + Quote(table.header[static_cast<std::size_t>(dims)]) + "; " +
                           usage);
  }
  QueryTable out;
  out.dims = dims;
  out.coords = std::move(table.values);
  out.lines = std::move(table.lines);
  return out;
}

}  // namespace brdf::interp
