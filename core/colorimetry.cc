#include "core/colorimetry.h"

#include <algorithm>
#include <charconv>
#include <cmath>
#include <optional>
#include <sstream>

namespace brdf {
namespace {

std::string Fmt(double v) {
  std::ostringstream s;
  s.precision(10);
  s << v;
  return s.str();
}

struct Token {
  std::string text;
  std::size_t line = 0;  // 1-based
};

// Splits one line on blanks; a double-quoted string is one token (without its quotes).
std::vector<std::string> SplitLine(std::string_view line) {
  std::vector<std::string> out;
  std::size_t i = 0;
  while (i < line.size()) {
    while (i < line.size() && (line[i] == ' ' || line[i] == '\t' || line[i] == '\r')) ++i;
    if (i >= line.size()) break;
    if (line[i] == '"') {
      const std::size_t end = line.find('"', i + 1);
      const std::size_t stop = end == std::string_view::npos ? line.size() : end;
      out.emplace_back(line.substr(i + 1, stop - i - 1));
      i = stop + 1;
    } else {
      std::size_t j = i;
      while (j < line.size() && line[j] != ' ' && line[j] != '\t' && line[j] != '\r') ++j;
      out.emplace_back(line.substr(i, j - i));
      i = j;
    }
  }
  return out;
}

std::optional<double> ParseDouble(std::string_view s) {
  double v = 0;
  const char* end = s.data() + s.size();
  const auto [ptr, ec] = std::from_chars(s.data(), end, v);
  if (ec != std::errc() || ptr != end || !std::isfinite(v)) return std::nullopt;
  return v;
}

std::optional<long> ParseCount(std::string_view s) {
  long v = 0;
  const char* end = s.data() + s.size();
  const auto [ptr, ec] = std::from_chars(s.data(), end, v);
  if (ec != std::errc() || ptr != end || v < 0) return std::nullopt;
  return v;
}

Status ParseError(std::size_t line, const std::string& what) {
  return InvalidArgument("spectral table, line " + std::to_string(line) + ": " + what);
}

enum class Section { kHeader, kFormat, kData, kDone };

// What a table's lines hold, read before the fields and sets are made sense of.
struct TableText {
  Section section = Section::kHeader;  // where the text ended
  std::vector<Token> format, data;
  std::optional<long> declared_fields, declared_sets, declared_bands;
  std::optional<double> declared_start_nm, declared_end_nm;
  std::size_t format_line = 0, data_line = 0;  // of BEGIN_DATA_FORMAT and BEGIN_DATA
  bool have_kind = false;
};

// A line of the header: the table's kind (the first line), the start of a section, or a key.
Status ReadHeaderLine(const std::vector<std::string>& tokens, std::size_t line_no, TableText& t,
                      SpectralTable& table) {
  const std::string& key = tokens[0];
  if (!t.have_kind) {
    table.kind = key;
    t.have_kind = true;
  } else if (key == "BEGIN_DATA_FORMAT") {
    t.section = Section::kFormat;
    t.format_line = line_no;
  } else if (key == "BEGIN_DATA") {
    if (t.format_line == 0) {
      return ParseError(line_no,
                        "BEGIN_DATA before any BEGIN_DATA_FORMAT; the field names "
                        "must come first");
    }
    t.section = Section::kData;
    t.data_line = line_no;
  } else if (key == "DISPLAY" && tokens.size() > 1) {
    table.name = tokens[1];
  } else if (key == "SPECTRAL_START_NM" || key == "SPECTRAL_END_NM") {
    const std::optional<double> nm =
        tokens.size() > 1 ? ParseDouble(tokens[1]) : std::optional<double>();
    if (!nm) return ParseError(line_no, key + " needs a wavelength in nm");
    (key == "SPECTRAL_START_NM" ? t.declared_start_nm : t.declared_end_nm) = nm;
  } else if (key == "NUMBER_OF_FIELDS" || key == "NUMBER_OF_SETS" || key == "SPECTRAL_BANDS") {
    const std::optional<long> n = tokens.size() > 1 ? ParseCount(tokens[1]) : std::optional<long>();
    if (!n) return ParseError(line_no, key + " needs a non-negative integer");
    (key == "NUMBER_OF_FIELDS" ? t.declared_fields
     : key == "NUMBER_OF_SETS" ? t.declared_sets
                               : t.declared_bands) = n;
  }
  return Status::Ok();
}

// A line of the format or data section: its tokens into `into`, up to `end_key`, which closes
// the section (the text goes on in `after`).
void ReadSectionLine(const std::vector<std::string>& tokens, std::size_t line_no,
                     std::string_view end_key, Section after, std::vector<Token>& into,
                     Section& section) {
  for (const std::string& token : tokens) {
    if (token == end_key) {
      section = after;
      return;
    }
    into.push_back({token, line_no});
  }
}

// The text line by line (blank lines and # comments skipped) up to END_DATA.
Result<TableText> ReadTableText(std::string_view text, SpectralTable& table) {
  TableText t;
  std::size_t line_no = 0;
  std::size_t pos = 0;
  while (pos <= text.size() && t.section != Section::kDone) {
    const std::size_t nl = text.find('\n', pos);
    const std::string_view line =
        text.substr(pos, nl == std::string_view::npos ? std::string_view::npos : nl - pos);
    pos = nl == std::string_view::npos ? text.size() + 1 : nl + 1;
    ++line_no;
    const std::vector<std::string> tokens = SplitLine(line);
    if (tokens.empty() || tokens[0].starts_with('#')) continue;
    switch (t.section) {
      case Section::kHeader:
        BRDF_RETURN_IF_ERROR(ReadHeaderLine(tokens, line_no, t, table));
        break;
      case Section::kFormat:
        ReadSectionLine(tokens, line_no, "END_DATA_FORMAT", Section::kHeader, t.format, t.section);
        break;
      case Section::kData:
        ReadSectionLine(tokens, line_no, "END_DATA", Section::kDone, t.data, t.section);
        break;
      case Section::kDone:
        break;
    }
  }
  return t;
}

// Both sections present and closed, and the format as long as NUMBER_OF_FIELDS says.
Status CheckTableText(const TableText& t) {
  if (!t.have_kind) return InvalidArgument("spectral table: the text is empty");
  if (t.format_line == 0) {
    return InvalidArgument(
        "spectral table: no BEGIN_DATA_FORMAT section; is this a colord "
        ".sp/.cmf file?");
  }
  if (t.section == Section::kFormat) {
    return ParseError(t.format_line, "BEGIN_DATA_FORMAT is never closed by END_DATA_FORMAT");
  }
  if (t.data_line == 0) return InvalidArgument("spectral table: no BEGIN_DATA section");
  if (t.section == Section::kData) {
    return ParseError(t.data_line, "BEGIN_DATA is never closed by END_DATA");
  }
  if (t.declared_fields && static_cast<std::size_t>(*t.declared_fields) != t.format.size()) {
    return ParseError(t.format_line, "NUMBER_OF_FIELDS says " + std::to_string(*t.declared_fields) +
                                         " but the format names " +
                                         std::to_string(t.format.size()) + " fields");
  }
  return Status::Ok();
}

enum class Column { kSpectral, kSampleId, kOther };

// Which column holds what; the SPEC_<nm> fields' wavelengths into the table.
Result<std::vector<Column>> ReadColumns(const TableText& t, SpectralTable& table) {
  std::vector<Column> columns;
  for (const Token& f : t.format) {
    if (f.text.starts_with("SPEC_")) {
      const std::optional<double> nm = ParseDouble(std::string_view(f.text).substr(5));
      if (!nm) return ParseError(f.line, "field " + f.text + " does not name a wavelength");
      table.wavelengths_nm.push_back(*nm);
      columns.push_back(Column::kSpectral);
    } else {
      columns.push_back(f.text == "SAMPLE_ID" ? Column::kSampleId : Column::kOther);
    }
  }
  if (table.wavelengths_nm.empty()) {
    return ParseError(t.format_line, "the format has no SPEC_<nm> fields, so no spectrum");
  }
  return columns;
}

// The header's range, when complete, is authoritative: colord's illuminant/CIE-A.sp says
// 300–830 nm in 531 bands but names its fields SPEC_300000, SPEC_301000, …
Status ApplyDeclaredRange(const TableText& t, SpectralTable& table) {
  if (!(t.declared_start_nm && t.declared_end_nm && t.declared_bands)) return Status::Ok();
  const std::size_t bands = static_cast<std::size_t>(*t.declared_bands);
  if (bands != table.wavelengths_nm.size()) {
    return ParseError(t.format_line,
                      "SPECTRAL_BANDS says " + std::to_string(bands) + " but the format has " +
                          std::to_string(table.wavelengths_nm.size()) + " SPEC_ fields");
  }
  const double step =
      bands > 1 ? (*t.declared_end_nm - *t.declared_start_nm) / static_cast<double>(bands - 1) : 0;
  for (std::size_t k = 0; k < bands; ++k) {
    table.wavelengths_nm[k] = *t.declared_start_nm + step * static_cast<double>(k);
  }
  return Status::Ok();
}

// The data, set by set: the spectral values and (when a SAMPLE_ID field is named) the ids.
Status ReadSets(const TableText& t, const std::vector<Column>& columns, SpectralTable& table) {
  if (t.data.size() % columns.size() != 0) {
    return ParseError(t.data_line, std::to_string(t.data.size()) +
                                       " values do not fill whole sets of " +
                                       std::to_string(columns.size()) + " fields");
  }
  const std::size_t n_sets = t.data.size() / columns.size();
  if (t.declared_sets && static_cast<std::size_t>(*t.declared_sets) != n_sets) {
    return ParseError(t.data_line, "NUMBER_OF_SETS says " + std::to_string(*t.declared_sets) +
                                       " but the data holds " + std::to_string(n_sets));
  }
  const bool has_ids =
      std::find(columns.begin(), columns.end(), Column::kSampleId) != columns.end();
  for (std::size_t s = 0; s < n_sets; ++s) {
    std::vector<double> values;
    values.reserve(table.wavelengths_nm.size());
    for (std::size_t c = 0; c < columns.size(); ++c) {
      const Token& token = t.data[s * columns.size() + c];
      if (columns[c] == Column::kSampleId) {
        table.set_ids.push_back(token.text);
      } else if (columns[c] == Column::kSpectral) {
        const std::optional<double> v = ParseDouble(token.text);
        if (!v) {
          return ParseError(token.line, "value '" + token.text + "' of field " + t.format[c].text +
                                            " in set " + std::to_string(s + 1) +
                                            " is not a number");
        }
        values.push_back(*v);
      }
    }
    table.sets.push_back(std::move(values));
  }
  if (!has_ids) table.set_ids.clear();
  return Status::Ok();
}

}  // namespace

Result<SpectralTable> ParseSpectralTable(std::string_view text) {
  SpectralTable table;
  BRDF_ASSIGN_OR_RETURN(const TableText t, ReadTableText(text, table));
  BRDF_RETURN_IF_ERROR(CheckTableText(t));
  BRDF_ASSIGN_OR_RETURN(const std::vector<Column> columns, ReadColumns(t, table));
  BRDF_RETURN_IF_ERROR(ApplyDeclaredRange(t, table));
  BRDF_RETURN_IF_ERROR(ReadSets(t, columns, table));
  return table;
}

Result<Spectrum> SpectralTable::SetAsSpectrum(std::size_t index) const {
  const std::string what = "spectral table '" + name + "'";
  if (index >= sets.size()) {
    return InvalidArgument(what + " has " + std::to_string(sets.size()) +
                           " sets; there is no set " + std::to_string(index));
  }
  const std::size_t n = wavelengths_nm.size();
  if (n == 0 || sets[index].size() != n) {
    return InvalidArgument(what + ": set " + std::to_string(index) + " has " +
                           std::to_string(sets[index].size()) + " values for " + std::to_string(n) +
                           " wavelengths");
  }
  WavelengthGrid grid{wavelengths_nm.front(), n > 1 ? wavelengths_nm[1] - wavelengths_nm[0] : 1.0,
                      n};
  if (grid.step_nm <= 0) {
    return InvalidArgument(what + ": wavelengths must increase (" + Fmt(wavelengths_nm[0]) +
                           " nm is followed by " + Fmt(wavelengths_nm[1]) + " nm)");
  }
  for (std::size_t k = 0; k < n; ++k) {
    if (std::fabs(wavelengths_nm[k] - grid.at(k)) > 1e-6) {
      return InvalidArgument(what + ": wavelengths are not evenly spaced (" +
                             Fmt(wavelengths_nm[k]) + " nm where " + Fmt(grid.at(k)) +
                             " nm was expected); resample the table first");
    }
  }
  return Spectrum{grid, sets[index]};
}

Result<ColorMatchingFunctions> ColorMatchingFunctionsFromTable(const SpectralTable& table) {
  if (table.sets.size() != 3) {
    return InvalidArgument("colour-matching functions: table '" + table.name + "' has " +
                           std::to_string(table.sets.size()) +
                           " sets; a CMF table has three (x̄, ȳ, z̄)");
  }
  BRDF_ASSIGN_OR_RETURN(Spectrum x, table.SetAsSpectrum(0));
  BRDF_ASSIGN_OR_RETURN(Spectrum y, table.SetAsSpectrum(1));
  BRDF_ASSIGN_OR_RETURN(Spectrum z, table.SetAsSpectrum(2));
  return ColorMatchingFunctions{std::move(x), std::move(y), std::move(z)};
}

Result<Xyz> ReflectanceToXyz(const Spectrum& reflectance, const Spectrum& illuminant,
                             const ColorMatchingFunctions& cmf) {
  BRDF_RETURN_IF_ERROR(ValidateSpectrum(reflectance, "reflectance"));
  const WavelengthGrid& grid = reflectance.grid;
  const std::pair<const Spectrum*, const char*> inputs[] = {
      {&illuminant, "illuminant"}, {&cmf.x_bar, "x̄"}, {&cmf.y_bar, "ȳ"}, {&cmf.z_bar, "z̄"}};
  std::vector<double> on_grid[4];
  for (int i = 0; i < 4; ++i) {
    Result<Spectrum> r = Resample(*inputs[i].first, grid);
    if (!r.ok()) {
      return r.status().WithContext(std::string("colour of a reflectance: the ") +
                                    inputs[i].second + " does not cover the reflectance's grid");
    }
    on_grid[i] = std::move(r).value().values;
  }
  const std::vector<double>& s = on_grid[0];
  double norm = 0, x = 0, y = 0, z = 0;
  for (std::size_t k = 0; k < grid.count; ++k) {
    const double rs = reflectance.values[k] * s[k];
    norm += s[k] * on_grid[2][k];
    x += rs * on_grid[1][k];
    y += rs * on_grid[2][k];
    z += rs * on_grid[3][k];
  }
  if (!(norm > 0)) {
    return InvalidArgument("colour of a reflectance: the illuminant has no luminance (Σ S·ȳ = " +
                           Fmt(norm) + ") over " + Fmt(grid.start_nm) + "–" + Fmt(grid.last_nm()) +
                           " nm; check the illuminant table");
  }
  return Xyz{x / norm, y / norm, z / norm};
}

Result<Xyz> WhitePoint(const Spectrum& illuminant, const ColorMatchingFunctions& cmf,
                       const WavelengthGrid& grid) {
  return ReflectanceToXyz(Spectrum{grid, std::vector<double>(grid.count, 1.0)}, illuminant, cmf);
}

Result<Chromaticity> ToChromaticity(const Xyz& c) {
  const double sum = c.X + c.Y + c.Z;
  if (!std::isfinite(sum) || sum <= 0) {
    return InvalidArgument("chromaticity: X + Y + Z = " + Fmt(sum) +
                           "; a black (or invalid) colour has no chromaticity");
  }
  return Chromaticity{c.X / sum, c.Y / sum};
}

Rgb XyzToLinearSrgb(const Xyz& c) {
  // IEC 61966-2-1 primaries and D65 white (x, y) = (0.3127, 0.3290), full-precision inverse.
  return {3.2404542 * c.X - 1.5371385 * c.Y - 0.4985314 * c.Z,
          -0.9692660 * c.X + 1.8760108 * c.Y + 0.0415560 * c.Z,
          0.0556434 * c.X - 0.2040259 * c.Y + 1.0572252 * c.Z};
}

double EncodeSrgbComponent(double linear) {
  const double v = std::clamp(std::isnan(linear) ? 0.0 : linear, 0.0, 1.0);
  return v <= 0.0031308 ? 12.92 * v : 1.055 * std::pow(v, 1.0 / 2.4) - 0.055;
}

Rgb EncodeSrgb(const Rgb& linear) {
  return {EncodeSrgbComponent(linear.r), EncodeSrgbComponent(linear.g),
          EncodeSrgbComponent(linear.b)};
}

}  // namespace brdf
