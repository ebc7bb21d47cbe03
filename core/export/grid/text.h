// The text side of a grid export: the grid as CSV (one row per cell), and the JSON description
// that travels next to an .npy file (which holds only numbers) so that its axes, band wavelengths,
// quantity and unit are never guessed.
#pragma once

#include <cstdint>
#include <ostream>
#include <string>
#include <vector>

#include "core/export/grid/regular_grid.h"
#include "core/export/session_data.h"

namespace brdf::exports {

// What the grid holds, for the headers.
struct GridExportInfo {
  std::int64_t session_id = 0;
  std::string session_name;
  Quantity quantity = Quantity::kBrdf;
  std::string method;             // the interpolation method ("octant", …)
  std::size_t samples = 0;        // sample readings the interpolator was built from
  std::size_t skipped = 0;        // sample readings left out
  std::string dtype = "float64";  // the .npy's element type ("float64" or "float32")
};

// How the interpolant was made, so that two grids made differently can be told apart.
struct InterpolantInfo {
  bool mirror_phi = false;
  bool reciprocity = false;
  std::vector<double> axis_scale;  // empty: all 1
  std::string fill_json;           // the fill policy and its counts (FillTally::Json()); or empty
  // Where the method measured and blended (interp::CoordinatesName): "incidence" or
  // "half_difference" (axis_scale then multiplies the half/difference axes).
  std::string coordinates = "incidence";
  // What the method blended (interp::TrendName): "none" or "bivariate".
  std::string trend = "none";
};

// A GridSink writing CSV: '#' comment lines documenting the quantity, unit, angles and axes, then
//   theta_i,theta_o,phi,status,<λ1>,<λ2>,…      (spectral columns headed by wavelength in nm)
// one row per cell in C order (θi, θo, φ), "nan" in the spectral columns of unfilled cells, and a
// final comment with the counts per status. Errors: kIoError when the stream fails.
class CsvGridWriter : public GridSink {
 public:
  CsvGridWriter(std::ostream& out, GridExportInfo info) : out_(out), info_(std::move(info)) {}
  Status Begin(const RegularGrid& grid, const WavelengthGrid& bands) override;
  Status WriteSlice(std::size_t theta_i_index, std::span<const double> values,
                    std::span<const interp::InterpStatus> statuses) override;
  Status Finish(const GridReport& report) override;

 private:
  std::ostream& out_;
  GridExportInfo info_;
  RegularGrid grid_;
  WavelengthGrid bands_;
  std::string buffer_;
};

// A JSON object describing an .npy grid export: shape and axis order, each axis (start, step,
// count, in degrees), the wavelengths, quantity, unit, method, symmetry options ("mirror_phi",
// "reciprocity"), "coordinates" ("incidence" or "half_difference"), "trend" ("none" or
// "bivariate"), "axis_scale" (null: all 1),
// "fill" (policy and per-provenance counts), "uncertainty" (`uncertainty_json`, a JSON object
// naming the uncertainty arrays beside the grid: fill/uncertain_chain.h UncertaintyJson; left
// out when empty), and the counts per status.
std::string GridDescriptionJson(const RegularGrid& grid, const WavelengthGrid& bands,
                                const GridExportInfo& info, const GridReport& report,
                                const InterpolantInfo& how = {},
                                const std::string& uncertainty_json = "");

// Comment lines (without the leading "# ") shared by the text exports: the angle convention.
std::vector<std::string> AngleConventionLines();

}  // namespace brdf::exports
