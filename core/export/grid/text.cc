#include "core/export/grid/text.h"

#include <utility>

#include "core/export/number_text.h"
#include "core/json_text.h"

namespace brdf::exports {

std::vector<std::string> AngleConventionLines() {
  return {
      "angles in degrees; directions in the sample frame of brdfd's geometry convention "
      "(docs/geometry.md): θ from the surface normal, in [0, 90] above the surface;",
      "φ = |φo − φi| folded into [0, 180] is the relative azimuth of lamp and detector: "
      "180 = forward (specular) side, 0 = retro side; φ = 0 where θi or θo is 0",
  };
}

namespace {

std::string AxisText(const char* name, const GridAxis& a) {
  return std::string(name) + ": " + std::to_string(a.count) + " values from " +
         FormatNumber(a.start_deg) + " to " + FormatNumber(a.at(a.count - 1)) + " every " +
         FormatNumber(a.step_deg);
}

std::string AxisJson(const GridAxis& a) {
  return "{\"start\": " + FormatNumber(a.start_deg) + ", \"step\": " + FormatNumber(a.step_deg) +
         ", \"count\": " + std::to_string(a.count) + "}";
}

}  // namespace

Status CsvGridWriter::Begin(const RegularGrid& grid, const WavelengthGrid& bands) {
  grid_ = grid;
  bands_ = bands;
  std::string h;
  h += "# brdfd regular grid export: session " + std::to_string(info_.session_id);
  if (!info_.session_name.empty()) h += " \"" + info_.session_name + "\"";
  h += "\n# quantity: " + std::string(QuantityName(info_.quantity)) + " in " +
       QuantityUnit(info_.quantity) + ": " + QuantityDefinition(info_.quantity) + "\n";
  h += "# resampled by the " + info_.method + " interpolation method from " +
       std::to_string(info_.samples) + " sample readings (" + std::to_string(info_.skipped) +
       " left out)\n";
  for (const std::string& line : AngleConventionLines()) h += "# " + line + "\n";
  h += "# grid (θi, θo, φ), rows in C order (θi slowest, φ fastest): " +
       AxisText("θi", grid.theta_i) + "; " + AxisText("θo", grid.theta_o) + "; " +
       AxisText("φ", grid.phi) + "\n";
  h += "# status: ok, or why the method could not fill the cell (empty_octant, "
       "no_enclosing_simplex, outside_hull); its spectral values are then nan\n";
  h += "# spectral columns: headed by wavelength in nm, " + std::to_string(bands.count) +
       " bands from " + FormatNumber(bands.start_nm) + " to " + FormatNumber(bands.last_nm()) +
       " every " + FormatNumber(bands.step_nm) + " nm; values in " + QuantityUnit(info_.quantity) +
       (info_.quantity == Quantity::kRadiance
            ? " (per nm, not per band: Psychtoolbox and BrainardLab files hold " +
                  FormatNumber(bands.step_nm) + " × these values)"
            : std::string()) +
       "\n";
  h += "theta_i,theta_o,phi,status";
  for (std::size_t b = 0; b < bands.count; ++b) {
    h += ',';
    AppendNumber(h, bands.at(b));
  }
  h += '\n';
  out_ << h;
  if (!out_) return IoError("writing the grid CSV header failed: is the disk full or read-only?");
  return Status::Ok();
}

Status CsvGridWriter::WriteSlice(std::size_t theta_i_index, std::span<const double> values,
                                 std::span<const interp::InterpStatus> statuses) {
  const double theta_i = grid_.theta_i.at(theta_i_index);
  const std::size_t nb = bands_.count;
  buffer_.clear();
  for (std::size_t c = 0; c < statuses.size(); ++c) {
    AppendNumber(buffer_, theta_i);
    buffer_ += ',';
    AppendNumber(buffer_, grid_.theta_o.at(c / grid_.phi.count));
    buffer_ += ',';
    AppendNumber(buffer_, grid_.phi.at(c % grid_.phi.count));
    buffer_ += ',';
    buffer_ += interp::InterpStatusName(statuses[c]);
    for (std::size_t b = 0; b < nb; ++b) {
      buffer_ += ',';
      AppendNumber(buffer_, values[c * nb + b]);
    }
    buffer_ += '\n';
  }
  out_.write(buffer_.data(), static_cast<std::streamsize>(buffer_.size()));
  if (!out_) {
    return IoError("writing the grid CSV failed at θi slice " + std::to_string(theta_i_index) +
                   ": is the disk full?");
  }
  return Status::Ok();
}

Status CsvGridWriter::Finish(const GridReport& report) {
  out_ << "# " << report.Summary() << "\n";
  out_.flush();
  if (!out_) return IoError("flushing the grid CSV failed: is the disk full?");
  return Status::Ok();
}

std::string GridDescriptionJson(const RegularGrid& grid, const WavelengthGrid& bands,
                                const GridExportInfo& info, const GridReport& report,
                                const InterpolantInfo& how, const std::string& uncertainty_json) {
  std::string j = "{\n";
  j += "  \"format\": \"brdfd regular grid (.npy, " + info.dtype + ", C order)\",\n";
  j += "  \"dtype\": " + JsonString(info.dtype) + ",\n";
  j += "  \"axes\": [\"theta_i\", \"theta_o\", \"phi\", \"band\"],\n";
  j += "  \"shape\": [" + std::to_string(grid.theta_i.count) + ", " +
       std::to_string(grid.theta_o.count) + ", " + std::to_string(grid.phi.count) + ", " +
       std::to_string(bands.count) + "],\n";
  j += "  \"theta_i_deg\": " + AxisJson(grid.theta_i) + ",\n";
  j += "  \"theta_o_deg\": " + AxisJson(grid.theta_o) + ",\n";
  j += "  \"phi_deg\": " + AxisJson(grid.phi) + ",\n";
  j += "  \"wavelength_nm\": {\"start\": " + FormatNumber(bands.start_nm) +
       ", \"step\": " + FormatNumber(bands.step_nm) +
       ", \"count\": " + std::to_string(bands.count) + "},\n";
  j += "  \"angles\": " + JsonString(AngleConventionLines()[0] + " " + AngleConventionLines()[1]) +
       ",\n";
  j += "  \"session\": " + std::to_string(info.session_id) + ",\n";
  j += "  \"session_name\": " + JsonString(info.session_name) + ",\n";
  j += "  \"quantity\": " + JsonString(QuantityName(info.quantity)) + ",\n";
  j += "  \"unit\": " + JsonString(QuantityUnit(info.quantity)) + ",\n";
  j += "  \"definition\": " + JsonString(QuantityDefinition(info.quantity)) + ",\n";
  j += "  \"method\": " + JsonString(info.method) + ",\n";
  j += std::string("  \"mirror_phi\": ") + (how.mirror_phi ? "true" : "false") + ",\n";
  j += std::string("  \"reciprocity\": ") + (how.reciprocity ? "true" : "false") + ",\n";
  j += "  \"coordinates\": " + JsonString(how.coordinates) + ",\n";
  j += "  \"trend\": " + JsonString(how.trend) + ",\n";
  std::string scale = "null";
  if (!how.axis_scale.empty()) {
    scale = "[";
    for (std::size_t k = 0; k < how.axis_scale.size(); ++k) {
      scale += (k ? ", " : "") + FormatNumber(how.axis_scale[k]);
    }
    scale += "]";
  }
  j += "  \"axis_scale\": " + scale + ",\n";
  if (!how.fill_json.empty()) j += "  \"fill\": " + how.fill_json + ",\n";
  if (!uncertainty_json.empty()) j += "  \"uncertainty\": " + uncertainty_json + ",\n";
  j += "  \"samples\": " + std::to_string(info.samples) + ",\n";
  j += "  \"samples_left_out\": " + std::to_string(info.skipped) + ",\n";
  j += "  \"cells\": " + std::to_string(report.cells) + ",\n";
  j += "  \"filled\": " + std::to_string(report.filled) + ",\n";
  j += "  \"nan_cells\": " + std::to_string(report.nan_cells) + ",\n";
  j += "  \"by_status\": {";
  bool first = true;
  for (const auto& [status, n] : report.by_status) {
    if (!first) j += ", ";
    first = false;
    j += JsonString(interp::InterpStatusName(status)) + ": " + std::to_string(n);
  }
  j += "}\n}\n";
  return j;
}

}  // namespace brdf::exports
