#include "core/export/grid/regular_grid.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <memory>
#include <span>
#include <string>
#include <thread>
#include <utility>
#include <vector>

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
// Slices are computed two windows of at least half this many cells at a time (one computed while
// the other goes to the sink), which bounds the memory to about that many spectra (1° × 1° × 2°,
// 101 bands: twice 4 slices, 52 MB).
constexpr std::size_t kWindowCells = 65536;

// What every window of a resampling shares.
struct WindowShape {
  const SpectrumSource& source;
  const RegularGrid& grid;
  std::size_t values_per_cell;  // bands · planes
  unsigned threads;
  std::size_t batch_cells;  // BatchCells of the grid
  const CallContext& ctx;
};

// A window of whole θi slices, [first, first + slices): the cells' directions and answers.
struct GridWindow {
  std::size_t first = 0;
  std::size_t slices = 0;
  std::vector<double> directions;
  // Not zeroed when made (make_unique_for_overwrite): a source writes every row of a batch
  // (SpectrumSource::Spectra: its answer or NaN), as it overwrites a reused window's. Zeroing it
  // was a pass over ~100 MB per export at 401 bands, before the sources' own.
  std::unique_ptr<double[]> value_store;
  std::span<double> values;
  std::vector<interp::InterpStatus> statuses;
  void Size(std::size_t cells, std::size_t values_per_cell) {
    directions.resize(3 * cells);
    value_store = std::make_unique_for_overwrite<double[]>(cells * values_per_cell);
    values = std::span(value_store.get(), cells * values_per_cell);
    statuses.resize(cells);
  }
};

// Answers every cell of `w` in batches spread over the threads: batches of at most
// shape.batch_cells, as many as a multiple of the threads so that none waits on the last one.
Status ComputeWindow(const WindowShape& shape, GridWindow& w) {
  const RegularGrid& grid = shape.grid;
  const std::size_t slice_cells = grid.theta_o.count * grid.phi.count;
  const std::size_t cells = w.slices * slice_cells;
  const std::size_t threads = std::max<std::size_t>(1, shape.threads);
  const std::size_t batches = (cells + shape.batch_cells - 1) / shape.batch_cells;
  const std::size_t even = (batches + threads - 1) / threads * threads;
  const std::size_t batch = (cells + even - 1) / even;
  const std::size_t nb = shape.values_per_cell;
  return ParallelForChunks(cells, batch, shape.threads, shape.ctx, nullptr, 0, "grid resampling",
                           [&](std::size_t begin, std::size_t end) {
                             for (std::size_t c = begin; c < end; ++c) {
                               const std::size_t in_slice = c % slice_cells;
                               double* at = w.directions.data() + 3 * c;
                               at[0] = grid.theta_i.at(w.first + c / slice_cells);
                               at[1] = grid.theta_o.at(in_slice / grid.phi.count);
                               at[2] = grid.phi.at(in_slice % grid.phi.count);
                             }
                             shape.source.Spectra(
                                 std::span(w.directions).subspan(3 * begin, 3 * (end - begin)),
                                 std::span(w.statuses).subspan(begin, end - begin),
                                 w.values.subspan(begin * nb, (end - begin) * nb));
                           });
}

// Hands the slices of `w` to the sink in order, counting their statuses and reporting progress
// after each; stops between slices once `ctx` is cancelled or past its deadline.
Status SendWindow(const GridWindow& w, const RegularGrid& grid, std::size_t values_per_cell,
                  const CallContext& ctx, GridSink& sink, GridReport& report,
                  ProgressReporter& progress) {
  const std::size_t slice_cells = grid.theta_o.count * grid.phi.count;
  for (std::size_t s = 0; s < w.slices; ++s) {
    const auto slice_statuses = std::span(w.statuses).subspan(s * slice_cells, slice_cells);
    for (interp::InterpStatus st : slice_statuses) ++report.by_status[st];
    const std::size_t n = slice_cells * values_per_cell;
    BRDF_RETURN_IF_ERROR(sink.WriteSlice(w.first + s, w.values.subspan(s * n, n), slice_statuses));
    const std::size_t done = (w.first + s + 1) * slice_cells;
    progress.Report(done);
    if (ctx.cancelled() || ctx.expired()) {
      const std::string where = "grid resampling stopped after " + std::to_string(done) + " of " +
                                std::to_string(grid.cells()) + " cells";
      if (ctx.cancelled()) return Cancelled(where + ": " + ctx.cancel().reason());
      return Timeout(where + ": the deadline passed; allow more time or export a coarser grid");
    }
  }
  return Status::Ok();
}

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
  const std::size_t slice_cells = grid.theta_o.count * grid.phi.count;
  const WindowShape shape{
      source, grid, bands.count * planes, ResolveThreads(control.threads), BatchCells(grid.cells()),
      ctx};
  BRDF_RETURN_IF_ERROR(sink.Begin(grid, bands));

  GridReport report;
  report.cells = grid.cells();
  ProgressReporter progress(control.progress, report.cells);
  // Two windows of whole slices: while one is computed (on a thread of its own, which spreads its
  // batches over the threads), the calling thread hands the other's slices to the sink.
  const std::size_t window_slices = std::min(
      grid.theta_i.count, std::max<std::size_t>(1, kWindowCells / 2 / planes / slice_cells));
  // The second window only when the grid needs more than one: a small grid costs one window.
  std::array<GridWindow, 2> windows;
  const std::size_t window_count = grid.theta_i.count > window_slices ? 2 : 1;
  for (std::size_t k = 0; k < window_count; ++k) {
    windows[k].Size(window_slices * slice_cells, shape.values_per_cell);
  }
  GridWindow* ready = &windows[0];
  GridWindow* next = &windows[1];
  ready->slices = window_slices;
  BRDF_RETURN_IF_ERROR(ComputeWindow(shape, *ready));
  for (;;) {
    const std::size_t after = ready->first + ready->slices;
    Status computed;
    std::thread computing;
    if (after < grid.theta_i.count) {
      next->first = after;
      next->slices = std::min(window_slices, grid.theta_i.count - after);
      computing = std::thread([&] { computed = ComputeWindow(shape, *next); });
    }
    const Status sent =
        SendWindow(*ready, grid, shape.values_per_cell, ctx, sink, report, progress);
    if (computing.joinable()) computing.join();
    BRDF_RETURN_IF_ERROR(sent);
    BRDF_RETURN_IF_ERROR(computed);
    if (after >= grid.theta_i.count) break;
    std::swap(ready, next);
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
    BRDF_RETURN_IF_ERROR(
        sinks_[p]->WritePlane(theta_i_index, values, planes, p, bands_, statuses, plane_));
  }
  return Status::Ok();
}

Status GridSink::WritePlane(std::size_t theta_i_index, std::span<const double> rows,
                            std::size_t planes, std::size_t plane, std::size_t bands,
                            std::span<const interp::InterpStatus> statuses,
                            std::vector<double>& scratch) {
  scratch.resize(statuses.size() * bands);
  for (std::size_t c = 0; c < statuses.size(); ++c) {
    std::copy_n(rows.begin() + static_cast<std::ptrdiff_t>((c * planes + plane) * bands), bands,
                scratch.begin() + static_cast<std::ptrdiff_t>(c * bands));
  }
  return WriteSlice(theta_i_index, scratch, statuses);
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
