#include "core/export/regular_grid.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <string>

#include "core/export/number_text.h"

namespace brdf::exports {
namespace {

constexpr double kTheta = 90.0;
constexpr double kPhi = 180.0;

Result<GridAxis> MakeAxis(const char* name, double span, double step, GridPlacement placement) {
  const std::string where = std::string("grid step for ") + name + " (" + FormatNumber(step) + "°)";
  if (!std::isfinite(step) || step <= 0) {
    return InvalidArgument(where + " must be a positive number of degrees");
  }
  if (step > span) {
    return InvalidArgument(where + " is larger than the axis's span of " + FormatNumber(span) +
                           "°");
  }
  const double n = span / step;
  const double whole = std::round(n);
  if (std::abs(n - whole) > 1e-9 * std::max(1.0, whole)) {
    return InvalidArgument(where + " does not divide the " + FormatNumber(span) +
                           "° span into whole cells (" + FormatNumber(n) +
                           "); pick a divisor such as 0.5, 1, 2, 2.5, 5, 10");
  }
  const auto cells = static_cast<std::size_t>(whole);
  // The step is recomputed from the cell count so that the last node lands on the span exactly.
  const double exact = span / whole;
  if (placement == GridPlacement::kCellCentres) return GridAxis{exact / 2, exact, cells};
  return GridAxis{0.0, exact, cells + 1};
}

Status CheckAxis(const char* name, const GridAxis& a, double span) {
  const std::string where = std::string("grid axis ") + name;
  if (a.count == 0) return InvalidArgument(where + " has no values");
  if (!std::isfinite(a.start_deg) || !std::isfinite(a.step_deg) || a.step_deg <= 0) {
    return InvalidArgument(where + ": start and step must be finite, the step positive");
  }
  const double last = a.at(a.count - 1);
  const double slack = 1e-9;
  if (a.start_deg < -slack || last > span + slack) {
    return InvalidArgument(where + " runs from " + FormatNumber(a.start_deg) + "° to " +
                           FormatNumber(last) + "°, outside [0°, " + FormatNumber(span) + "°]");
  }
  return Status::Ok();
}

}  // namespace

Result<RegularGrid> MakeRegularGrid(double step_theta_i_deg, double step_theta_o_deg,
                                    double step_phi_deg, GridPlacement placement) {
  Result<GridAxis> ti = MakeAxis("θi", kTheta, step_theta_i_deg, placement);
  if (!ti.ok()) return ti.status();
  Result<GridAxis> to = MakeAxis("θo", kTheta, step_theta_o_deg, placement);
  if (!to.ok()) return to.status();
  Result<GridAxis> ph = MakeAxis("φ", kPhi, step_phi_deg, placement);
  if (!ph.ok()) return ph.status();
  return RegularGrid{*ti, *to, *ph};
}

Status ValidateRegularGrid(const RegularGrid& grid) {
  BRDF_RETURN_IF_ERROR(CheckAxis("θi", grid.theta_i, kTheta));
  BRDF_RETURN_IF_ERROR(CheckAxis("θo", grid.theta_o, kTheta));
  return CheckAxis("φ", grid.phi, kPhi);
}

std::string GridReport::Summary() const {
  std::string s = std::to_string(cells) + " cells: " + std::to_string(filled) + " ok, " +
                  std::to_string(nan_cells) + " NaN";
  std::string parts;
  for (const auto& [status, n] : by_status) {
    if (status == interp::InterpStatus::kOk) continue;
    if (!parts.empty()) parts += ", ";
    parts += std::to_string(n) + " " + interp::InterpStatusName(status);
  }
  if (!parts.empty()) s += " (" + parts + ")";
  return s;
}

Result<GridReport> ResampleOnGrid(const SpectrumSource& source, const RegularGrid& grid,
                                  const WavelengthGrid& bands, const RunControl& control,
                                  const CallContext& ctx, GridSink& sink) {
  BRDF_RETURN_IF_ERROR(ValidateRegularGrid(grid));
  if (!bands.valid()) {
    return InvalidArgument("resampling onto a grid: the wavelength grid is invalid (no bands)");
  }
  const std::size_t nb = bands.count;
  const std::size_t slice_cells = grid.theta_o.count * grid.phi.count;
  const unsigned threads = ResolveThreads(control.threads);
  BRDF_RETURN_IF_ERROR(sink.Begin(grid, bands));

  GridReport report;
  report.cells = grid.cells();
  ProgressReporter progress(control.progress, report.cells);
  std::vector<double> values(slice_cells * nb);
  std::vector<interp::InterpStatus> statuses(slice_cells);
  constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();

  for (std::size_t i = 0; i < grid.theta_i.count; ++i) {
    const double theta_i = grid.theta_i.at(i);
    BRDF_RETURN_IF_ERROR(ParallelFor(slice_cells, threads, ctx, &progress, i * slice_cells,
                                     "grid resampling", [&](std::size_t begin, std::size_t end) {
                                       for (std::size_t c = begin; c < end; ++c) {
                                         const IsoDirection at{theta_i,
                                                               grid.theta_o.at(c / grid.phi.count),
                                                               grid.phi.at(c % grid.phi.count)};
                                         std::span<double> out(values.data() + c * nb, nb);
                                         const interp::InterpStatus st = source(at, out);
                                         statuses[c] = st;
                                         if (st != interp::InterpStatus::kOk)
                                           std::fill(out.begin(), out.end(), kNaN);
                                       }
                                     }));
    for (interp::InterpStatus st : statuses) ++report.by_status[st];
    BRDF_RETURN_IF_ERROR(sink.WriteSlice(i, values, statuses));
  }
  const auto ok = report.by_status.find(interp::InterpStatus::kOk);
  report.filled = ok == report.by_status.end() ? 0 : ok->second;
  report.nan_cells = report.cells - report.filled;
  BRDF_RETURN_IF_ERROR(sink.Finish(report));
  progress.Finish();
  return report;
}

Status MemoryGrid::Begin(const RegularGrid& grid, const WavelengthGrid& bands) {
  grid_ = grid;
  bands_ = bands;
  values_.assign(grid.cells() * bands.count, 0.0);
  statuses_.assign(grid.cells(), interp::InterpStatus::kOk);
  return Status::Ok();
}

Status MemoryGrid::WriteSlice(std::size_t theta_i_index, std::span<const double> values,
                              std::span<const interp::InterpStatus> statuses) {
  const std::size_t slice_cells = grid_.theta_o.count * grid_.phi.count;
  if (theta_i_index >= grid_.theta_i.count || statuses.size() != slice_cells ||
      values.size() != slice_cells * bands_.count) {
    return Internal("MemoryGrid: slice " + std::to_string(theta_i_index) +
                    " does not fit the grid it was begun with");
  }
  std::copy(values.begin(), values.end(),
            values_.begin() + static_cast<std::ptrdiff_t>(theta_i_index * values.size()));
  std::copy(statuses.begin(), statuses.end(),
            statuses_.begin() + static_cast<std::ptrdiff_t>(theta_i_index * slice_cells));
  return Status::Ok();
}

Status MemoryGrid::Finish(const GridReport& report) {
  report_ = report;
  return Status::Ok();
}

}  // namespace brdf::exports
