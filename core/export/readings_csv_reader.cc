#include "core/export/readings_csv_reader.h"

#include <charconv>
#include <cmath>
#include <optional>

namespace brdf::exports {
namespace {

// One CSV line split into fields (RFC 4180 quotes: "" inside a quoted field is one ").
std::vector<std::string> SplitFields(std::string_view line) {
  std::vector<std::string> fields(1);
  bool quoted = false;
  for (std::size_t i = 0; i < line.size(); ++i) {
    const char c = line[i];
    if (quoted) {
      if (c == '"' && i + 1 < line.size() && line[i + 1] == '"') {
        fields.back() += '"';
        ++i;
      } else if (c == '"') {
        quoted = false;
      } else {
        fields.back() += c;
      }
    } else if (c == '"') {
      quoted = true;
    } else if (c == ',') {
      fields.emplace_back();
    } else if (c != '\r') {
      fields.back() += c;
    }
  }
  return fields;
}

std::optional<double> NumberOf(std::string_view text) {
  if (text == "nan") return std::nan("");
  double v = 0;
  const auto r = std::from_chars(text.data(), text.data() + text.size(), v);
  if (r.ec != std::errc() || r.ptr != text.data() + text.size()) return std::nullopt;
  return v;
}

// The column layout, found by header names.
struct Columns {
  std::size_t id = 0, kind = 0, theta_i = 0, phi_i = 0, theta_o = 0, phi_o = 0;
  std::vector<std::size_t> values, u;
  std::vector<double> wavelengths;
  bool has_kind = false;
  std::size_t count = 0;  // header fields
};

Result<Columns> ColumnsOf(const std::vector<std::string>& header, const std::string& where) {
  Columns c;
  c.count = header.size();
  std::vector<double> u_wavelengths;
  std::optional<std::size_t> id, ti, pi, to, po;
  for (std::size_t i = 0; i < header.size(); ++i) {
    const std::string& h = header[i];
    if (h == "id") id = i;
    if (h == "kind") c.kind = i, c.has_kind = true;
    if (h == "theta_i_deg") ti = i;
    if (h == "phi_i_deg") pi = i;
    if (h == "theta_o_deg") to = i;
    if (h == "phi_o_deg") po = i;
    if (std::optional<double> nm = NumberOf(h); nm && std::isfinite(*nm)) {
      c.values.push_back(i);
      c.wavelengths.push_back(*nm);
    } else if (h.starts_with("u_")) {
      std::optional<double> unm = NumberOf(std::string_view(h).substr(2));
      if (!unm) return InvalidArgument(where + ": column '" + h + "' is not u_<wavelength in nm>");
      c.u.push_back(i);
      u_wavelengths.push_back(*unm);
    }
  }
  if (!id || !ti || !pi || !to || !po) {
    return InvalidArgument(where +
                           ": the header lacks one of id, theta_i_deg, phi_i_deg, "
                           "theta_o_deg, phi_o_deg: is this a brdfd readings CSV?");
  }
  if (c.values.empty()) return InvalidArgument(where + ": no spectral columns (headed by nm)");
  if (!c.u.empty() && u_wavelengths != c.wavelengths) {
    return InvalidArgument(where + ": the u_<λ> columns do not match the spectral columns");
  }
  c.id = *id, c.theta_i = *ti, c.phi_i = *pi, c.theta_o = *to, c.phi_o = *po;
  return c;
}

Result<WavelengthGrid> GridOf(const std::vector<double>& nm, const std::string& where) {
  WavelengthGrid grid{nm.front(), nm.size() > 1 ? nm[1] - nm[0] : 1.0, nm.size()};
  for (std::size_t b = 0; b < nm.size(); ++b) {
    if (!(grid.step_nm > 0) || std::abs(nm[b] - grid.at(b)) > 1e-6 * grid.step_nm) {
      return InvalidArgument(where + ": the spectral columns are not evenly spaced in nm (at " +
                             std::to_string(nm[b]) + " nm)");
    }
  }
  return grid;
}

// The '#' lines that name the session and the quantity.
void ReadComment(std::string_view line, ReadingsCsv& out) {
  constexpr std::string_view kSession = "# brdfd readings export: session ";
  constexpr std::string_view kQuantity = "# quantity: ";
  if (line.starts_with(kSession)) {
    std::string_view rest = line.substr(kSession.size());
    std::int64_t id = 0;
    const auto r = std::from_chars(rest.data(), rest.data() + rest.size(), id);
    if (r.ec == std::errc()) out.session_id = id;
    const std::size_t q = rest.find('"'), q2 = rest.rfind('"');
    if (q != std::string_view::npos && q2 > q) out.session_name = rest.substr(q + 1, q2 - q - 1);
  } else if (line.starts_with(kQuantity)) {
    const std::string_view rest = line.substr(kQuantity.size());
    out.quantity = rest.substr(0, rest.find(' '));
  }
}

Result<ReadingsCsvRow> RowOf(const std::vector<std::string>& f, const Columns& c,
                             const std::string& where) {
  auto number = [&](std::size_t col, const char* what) -> Result<double> {
    std::optional<double> v = NumberOf(f[col]);
    if (!v) return InvalidArgument(where + ": " + what + " '" + f[col] + "' is not a number");
    return *v;
  };
  ReadingsCsvRow row;
  BRDF_ASSIGN_OR_RETURN(const double id, number(c.id, "id"));
  row.id = static_cast<std::int64_t>(id);
  if (c.has_kind) row.kind = f[c.kind];
  BRDF_ASSIGN_OR_RETURN(row.directions.theta_i, number(c.theta_i, "theta_i_deg"));
  BRDF_ASSIGN_OR_RETURN(row.directions.phi_i, number(c.phi_i, "phi_i_deg"));
  BRDF_ASSIGN_OR_RETURN(row.directions.theta_o, number(c.theta_o, "theta_o_deg"));
  BRDF_ASSIGN_OR_RETURN(row.directions.phi_o, number(c.phi_o, "phi_o_deg"));
  for (std::size_t col : c.values) {
    BRDF_ASSIGN_OR_RETURN(const double v, number(col, "value"));
    row.values.push_back(v);
  }
  bool all_u = !c.u.empty();
  for (std::size_t col : c.u) all_u = all_u && !f[col].empty();
  for (std::size_t col : c.u) {
    if (!all_u) break;
    BRDF_ASSIGN_OR_RETURN(const double v, number(col, "uncertainty"));
    row.u.push_back(v);
  }
  return row;
}

}  // namespace

Result<ReadingsCsv> ParseReadingsCsv(std::string_view text, std::string_view source) {
  ReadingsCsv out;
  std::optional<Columns> columns;
  std::size_t line_no = 0;
  for (std::size_t at = 0; at < text.size();) {
    std::size_t end = text.find('\n', at);
    if (end == std::string_view::npos) end = text.size();
    const std::string_view line = text.substr(at, end - at);
    at = end + 1;
    ++line_no;
    const std::string where = std::string(source) + ", line " + std::to_string(line_no);
    if (line.starts_with('#')) {
      ReadComment(line, out);
      continue;
    }
    if (line.empty() || line == "\r") continue;
    const std::vector<std::string> fields = SplitFields(line);
    if (!columns) {
      BRDF_ASSIGN_OR_RETURN(columns, ColumnsOf(fields, where));
      BRDF_ASSIGN_OR_RETURN(out.grid, GridOf(columns->wavelengths, where));
      out.has_u_columns = !columns->u.empty();
      continue;
    }
    if (fields.size() != columns->count) {
      return InvalidArgument(where + ": " + std::to_string(fields.size()) +
                             " fields where the header has " + std::to_string(columns->count));
    }
    BRDF_ASSIGN_OR_RETURN(ReadingsCsvRow row, RowOf(fields, *columns, where));
    out.rows.push_back(std::move(row));
  }
  if (!columns) {
    return InvalidArgument(std::string(source) + ": no header row: is this a brdfd readings CSV?");
  }
  return out;
}

}  // namespace brdf::exports
