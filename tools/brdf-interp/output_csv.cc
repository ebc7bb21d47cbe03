#include "tools/brdf-interp/output_csv.h"

#include <charconv>

#include "core/csv_field.h"
#include "core/interp/csv_table.h"

namespace brdf::interp_tool {

int MaxVertices(interp::Method method, int dims) {
  return method == interp::Method::kNearest ? 1 : dims + 1;
}

void AppendNumber(double x, std::string& out) {
  char buffer[32];
  const auto [end, ec] = std::to_chars(buffer, buffer + sizeof buffer, x);
  out.append(buffer, ec == std::errc() ? end : buffer);
}

std::string FormatHeader(const OutputLayout& layout) {
  std::string out;
  for (const char* name : interp::CoordinateColumns(layout.dims)) {
    out += name;
    out += ',';
  }
  out += "status";
  for (const std::string& w : layout.wavelength_headers) {
    out += ',';
    AppendCsvField(out, w);
  }
  if (layout.explain_vertices > 0) {
    for (int k = 0; k < layout.explain_vertices; ++k) out += ",v" + std::to_string(k);
    for (int k = 0; k < layout.explain_vertices; ++k) out += ",w" + std::to_string(k);
    out += ",detail";
  }
  out += '\n';
  return out;
}

void AppendRow(const OutputLayout& layout, std::span<const double> query,
               const interp::Interpolation& answer, std::string& out) {
  for (double x : query) {
    AppendNumber(x, out);
    out += ',';
  }
  out += interp::InterpStatusName(answer.status);
  const bool ok = answer.status == interp::InterpStatus::kOk;
  for (std::size_t b = 0; b < layout.wavelength_headers.size(); ++b) {
    out += ',';
    if (ok && b < answer.spectrum.size()) AppendNumber(answer.spectrum[b], out);
  }
  if (layout.explain_vertices > 0) {
    const auto k = static_cast<std::size_t>(layout.explain_vertices);
    for (std::size_t i = 0; i < k; ++i) {
      out += ',';
      if (i < answer.vertices.size()) out += std::to_string(answer.vertices[i].index);
    }
    for (std::size_t i = 0; i < k; ++i) {
      out += ',';
      if (i < answer.vertices.size()) AppendNumber(answer.vertices[i].weight, out);
    }
    out += ',';
    AppendCsvField(out, answer.detail);
  }
  out += '\n';
}

}  // namespace brdf::interp_tool
