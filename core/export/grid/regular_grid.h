// Resampling a session onto a regular grid over (θi, θo, φ), the form array tools want: the cells
// ask a SpectrumSource (the session's interpolator) for their spectra in batches of thousands
// (SpectrumSource::Spectra, which the octant method sorts by cell), in parallel, and the cells
// it cannot fill (an empty octant, outside the hull) hold NaN and are counted per status.
//
// The work goes slice by slice (one θi value at a time, C order θi, θo, φ, band) to a GridSink,
// so that a 1° grid of 101 bands (90 × 90 × 180 × 101 doubles, 1.2 GB) never has to sit in
// memory: the .npy and CSV writers stream it out. Slices are computed a window of at least 32,768
// cells at a time, on threads of their own, while the calling thread hands the window before to
// the sink (1° × 1° × 2°, 101 bands: two windows of 4 slices, 52 MB).
#pragma once

#include <cstddef>
#include <map>
#include <span>
#include <string>
#include <utility>
#include <vector>

#include "core/call_context.h"
#include "core/export/fill/spectrum_source.h"
#include "core/export/run_control.h"
#include "core/interp/interpolator.h"
#include "core/status.h"
#include "core/wavelength_grid.h"

namespace brdf::exports {

// Values start, start + step, …, count of them (degrees).
struct GridAxis {
  double start_deg = 0;
  double step_deg = 1;
  std::size_t count = 0;
  double at(std::size_t k) const { return start_deg + step_deg * static_cast<double>(k); }
  friend bool operator==(const GridAxis&, const GridAxis&) = default;
};

struct RegularGrid {
  GridAxis theta_i;
  GridAxis theta_o;
  GridAxis phi;  // relative azimuth φ = |φo − φi| in [0°, 180°], 180° the specular side
  std::size_t cells() const { return theta_i.count * theta_o.count * phi.count; }
  friend bool operator==(const RegularGrid&, const RegularGrid&) = default;
};

// Where the samples sit on θi, θo ∈ [0°, 90°] and φ ∈ [0°, 180°].
enum class GridPlacement {
  // The centres of span/step cells: 0.5·step, 1.5·step, … (1° steps: 90 × 90 × 180, MERL-like).
  kCellCentres,
  // The nodes 0, step, …, span, both ends included (1° steps: 91 × 91 × 181).
  kNodes,
};

// The grid with these steps (degrees). Errors (kInvalidArgument, naming the axis and value): a
// step that is not finite and positive, larger than its axis's span (90° for θ, 180° for φ), or
// that does not divide the span into whole cells (within 1e-9 of an integer count).
Result<RegularGrid> MakeRegularGrid(double step_theta_i_deg, double step_theta_o_deg,
                                    double step_phi_deg, GridPlacement placement);

// Checks a grid built by hand: every count > 0, steps finite and positive, every coordinate
// within θ ∈ [0°, 90°] and φ ∈ [0°, 180°]. The message names the axis.
Status ValidateRegularGrid(const RegularGrid& grid);

// What a resampling produced.
struct GridReport {
  std::size_t cells = 0;
  std::size_t filled = 0;     // cells with a spectrum (status ok)
  std::size_t nan_cells = 0;  // cells the source could not fill: NaN in every band
  std::map<interp::InterpStatus, std::size_t> by_status;  // each status seen (ok included)
  // "16200 cells: 15012 ok, 1188 NaN (1100 empty_octant, 88 no_enclosing_simplex)"
  std::string Summary() const;
};

// Receives the grid slice by slice, in θi order, from the calling thread.
class GridSink {
 public:
  virtual ~GridSink() = default;
  virtual Status Begin(const RegularGrid& grid, const WavelengthGrid& bands) = 0;
  // Slice `theta_i_index`: values[(j·nφ + k)·bands + b] and statuses[j·nφ + k] for θo index j and
  // φ index k; every value of a cell whose status is not ok is NaN.
  virtual Status WriteSlice(std::size_t theta_i_index, std::span<const double> values,
                            std::span<const interp::InterpStatus> statuses) = 0;
  // Plane `plane` of slice `theta_i_index` whose cells hold `planes` planes of `bands` values each
  // (rows[(c·planes + plane)·bands + b] for cell c; PlaneSplitSink), as WriteSlice takes that
  // plane gathered. This default gathers it into `scratch` and calls WriteSlice; a sink that
  // converts what it writes (NpyGridWriter's float32) reads it where it lies instead.
  virtual Status WritePlane(std::size_t theta_i_index, std::span<const double> rows,
                            std::size_t planes, std::size_t plane, std::size_t bands,
                            std::span<const interp::InterpStatus> statuses,
                            std::vector<double>& scratch);
  virtual Status Finish(const GridReport& report) = 0;
};

// Resamples `source` at every cell of `grid` (spectra of bands.count values) and streams the
// slices to `sink`. Errors: an invalid grid or band grid (kInvalidArgument), kCancelled /
// kTimeout from `ctx` (the sink is not finished then: discard its output), and the sink's own.
Result<GridReport> ResampleOnGrid(const SpectrumSource& source, const RegularGrid& grid,
                                  const WavelengthGrid& bands, const RunControl& control,
                                  const CallContext& ctx, GridSink& sink);

// The same for a source whose rows hold `planes` planes of bands.count values each (a value and
// its uncertainties: fill/uncertain_chain.h): the sink's slices then hold planes · bands values
// per cell, plane after plane (PlaneSplitSink hands each plane to a sink of its own). The window
// of slices shrinks by `planes` so the memory stays as without. planes ≥ 1.
Result<GridReport> ResampleOnGrid(const SpectrumSource& source, const RegularGrid& grid,
                                  const WavelengthGrid& bands, const RunControl& control,
                                  const CallContext& ctx, GridSink& sink, std::size_t planes);

// A GridSink taking slices of `sinks.size()` planes per cell and handing plane p of every cell
// to sinks[p] (null: that plane is dropped), each as an ordinary slice of bands values per cell.
// The sinks must outlive it. Errors: the sinks' own, kInternal for a slice of the wrong size.
class PlaneSplitSink : public GridSink {
 public:
  explicit PlaneSplitSink(std::vector<GridSink*> sinks) : sinks_(std::move(sinks)) {}
  Status Begin(const RegularGrid& grid, const WavelengthGrid& bands) override;
  Status WriteSlice(std::size_t theta_i_index, std::span<const double> values,
                    std::span<const interp::InterpStatus> statuses) override;
  Status Finish(const GridReport& report) override;

 private:
  std::vector<GridSink*> sinks_;
  std::size_t bands_ = 0;
  std::vector<double> plane_;
};

// A sink that keeps the whole grid in memory: for small grids, tests and callers that post-process.
class MemoryGrid : public GridSink {
 public:
  Status Begin(const RegularGrid& grid, const WavelengthGrid& bands) override;
  Status WriteSlice(std::size_t theta_i_index, std::span<const double> values,
                    std::span<const interp::InterpStatus> statuses) override;
  Status Finish(const GridReport& report) override;

  const RegularGrid& grid() const { return grid_; }
  const WavelengthGrid& bands() const { return bands_; }
  const GridReport& report() const { return report_; }
  // All values in C order (θi, θo, φ, band), and one status per cell.
  const std::vector<double>& values() const { return values_; }
  const std::vector<interp::InterpStatus>& statuses() const { return statuses_; }
  std::size_t CellIndex(std::size_t i, std::size_t j, std::size_t k) const {
    return (i * grid_.theta_o.count + j) * grid_.phi.count + k;
  }
  std::span<const double> spectrum(std::size_t i, std::size_t j, std::size_t k) const {
    return {values_.data() + CellIndex(i, j, k) * bands_.count, bands_.count};
  }

 private:
  RegularGrid grid_;
  WavelengthGrid bands_;
  GridReport report_;
  std::vector<double> values_;
  std::vector<interp::InterpStatus> statuses_;
};

}  // namespace brdf::exports
