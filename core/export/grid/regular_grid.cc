#include "core/export/grid/regular_grid.h"

#include <algorithm>
#include <cmath>
#include <string>

#include "core/export/number_text.h"

namespace brdf::exports {
namespace {

constexpr double kTheta = 90.0;
constexpr double kPhi = 180.0;
// Cells answered as one SpectrumSource::Spectra batch: enough for the octant method to sort them
// by cell (a quarter of a query per cell, about 6,000 on 50,000 readings;
// core/interp/octant/octant.h), yet at least 64 batches per grid for the progress line and a prompt
// cancel (1° × 1° × 2°: 11,390 cells).
std::size_t BatchCells(std::size_t cells) {
  return std::clamp<std::size_t>(cells / 64, 1024, 16384);
}
// Slices are computed a window of at least this many cells at a time before they go to the sink,
// which bounds the memory to about that many spectra (1° × 1° × 2°, 101 bands: 8 slices, 52 MB).
constexpr std::size_t kWindowCells = 65536;

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
  BRDF_ASSIGN_OR_RETURN(GridAxis ti, MakeAxis("θi", kTheta, step_theta_i_deg, placement));
  BRDF_ASSIGN_OR_RETURN(GridAxis to, MakeAxis("θo", kTheta, step_theta_o_deg, placement));
  BRDF_ASSIGN_OR_RETURN(GridAxis ph, MakeAxis("φ", kPhi, step_phi_deg, placement));
  return RegularGrid{ti, to, ph};
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
  return ResampleOnGrid(source, grid, bands, control, ctx, sink, 1);
}

Result<GridReport> ResampleOnGrid(const SpectrumSource& source, const RegularGrid& grid,
                                  const WavelengthGrid& bands, const RunControl& control,
                                  const CallContext& ctx, GridSink& sink, std::size_t planes) {
  BRDF_RETURN_IF_ERROR(ValidateRegularGrid(grid));
  if (!bands.valid()) {
    return InvalidArgument("resampling onto a grid: the wavelength grid is invalid (no bands)");
  }
  if (planes < 1) return InvalidArgument("resampling onto a grid: planes must be at least 1");
  const std::size_t nb = bands.count * planes;  // values per cell
  const std::size_t slice_cells = grid.theta_o.count * grid.phi.count;
  const unsigned threads = ResolveThreads(control.threads);
  BRDF_RETURN_IF_ERROR(sink.Begin(grid, bands));

  GridReport report;
  report.cells = grid.cells();
  ProgressReporter progress(control.progress, report.cells);
  // Whole slices go through in windows of at least kWindowCells cells, each window in batches of
  // BatchCells (SpectrumSource::Spectra) spread over the threads, then slice by slice to the sink.
  const std::size_t window_slices =
      std::min(grid.theta_i.count, std::max<std::size_t>(1, kWindowCells / planes / slice_cells));
  std::vector<double> directions(3 * window_slices * slice_cells);
  std::vector<double> values(window_slices * slice_cells * nb);
  std::vector<interp::InterpStatus> statuses(window_slices * slice_cells);

  for (std::size_t first = 0; first < grid.theta_i.count; first += window_slices) {
    const std::size_t slices = std::min(window_slices, grid.theta_i.count - first);
    BRDF_RETURN_IF_ERROR(ParallelForChunks(
        slices * slice_cells, BatchCells(report.cells), threads, ctx, &progress,
        first * slice_cells, "grid resampling", [&](std::size_t begin, std::size_t end) {
          for (std::size_t c = begin; c < end; ++c) {
            const std::size_t in_slice = c % slice_cells;
            double* at = directions.data() + 3 * c;
            at[0] = grid.theta_i.at(first + c / slice_cells);
            at[1] = grid.theta_o.at(in_slice / grid.phi.count);
            at[2] = grid.phi.at(in_slice % grid.phi.count);
          }
          source.Spectra(std::span(directions).subspan(3 * begin, 3 * (end - begin)),
                         std::span(statuses).subspan(begin, end - begin),
                         std::span(values).subspan(begin * nb, (end - begin) * nb));
        }));
    for (std::size_t s = 0; s < slices; ++s) {
      const auto slice_statuses = std::span(statuses).subspan(s * slice_cells, slice_cells);
      for (interp::InterpStatus st : slice_statuses) ++report.by_status[st];
      BRDF_RETURN_IF_ERROR(sink.WriteSlice(
          first + s, std::span(values).subspan(s * slice_cells * nb, slice_cells * nb),
          slice_statuses));
    }
  }
  const auto ok = report.by_status.find(interp::InterpStatus::kOk);
  report.filled = ok == report.by_status.end() ? 0 : ok->second;
  report.nan_cells = report.cells - report.filled;
  BRDF_RETURN_IF_ERROR(sink.Finish(report));
  progress.Finish();
  return report;
}

Status PlaneSplitSink::Begin(const RegularGrid& grid, const WavelengthGrid& bands) {
  bands_ = bands.count;
  plane_.resize(grid.theta_o.count * grid.phi.count * bands_);
  for (GridSink* sink : sinks_) {
    if (sink != nullptr) BRDF_RETURN_IF_ERROR(sink->Begin(grid, bands));
  }
  return Status::Ok();
}

Status PlaneSplitSink::WriteSlice(std::size_t theta_i_index, std::span<const double> values,
                                  std::span<const interp::InterpStatus> statuses) {
  const std::size_t planes = sinks_.size();
  if (values.size() != statuses.size() * planes * bands_ ||
      plane_.size() != statuses.size() * bands_) {
    return Internal("PlaneSplitSink: slice " + std::to_string(theta_i_index) + " does not hold " +
                    std::to_string(planes) + " planes per cell");
  }
  for (std::size_t p = 0; p < planes; ++p) {
    if (sinks_[p] == nullptr) continue;
    for (std::size_t c = 0; c < statuses.size(); ++c) {
      std::copy_n(values.begin() + static_cast<std::ptrdiff_t>((c * planes + p) * bands_), bands_,
                  plane_.begin() + static_cast<std::ptrdiff_t>(c * bands_));
    }
    BRDF_RETURN_IF_ERROR(sinks_[p]->WriteSlice(theta_i_index, plane_, statuses));
  }
  return Status::Ok();
}

Status PlaneSplitSink::Finish(const GridReport& report) {
  for (GridSink* sink : sinks_) {
    if (sink != nullptr) BRDF_RETURN_IF_ERROR(sink->Finish(report));
  }
  return Status::Ok();
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
