// Calibrating an interpolated value's interpolation term against the session's own readings
// (docs/uncertainty.md, "The interpolation term"). The vertices' spread s (blend.h,
// InterpolationSpread) says how much the BRDF changes across a cell, not how far the blend is
// from the truth: on the simulator's materials it is 1.5–4 times too wide, by a factor that
// differs from material to material. The calibrated term is
//
//     u_int(λ) = c(λ) · s(λ),
//
// with c fitted per session from held-out readings: readings left out of the index, predicted
// from the rest at their own poses, their residuals r compared with c · s there. A split-conformal
// rank (the ⌈(n + 1) · coverage⌉-th smallest of n) keeps a small calibration set from claiming
// more than it has. With CalibrationTarget::size_bins > 1 c also depends on the cell's size h
// (CellSize, the vertices' weighted spread of positions): the held-out readings are binned by h
// (equal counts), each bin gets its own c — the pooled c times the ratio of the bin's
// kSizeBinQuantile need to the pooled one — never smaller than a smaller bin's, and a cell larger
// than every held-out one either gets c · h / h_max or is not estimated (SizeBeyond). Delaunay's
// large cells across the data's gaps err more, relative to s, than its small ones (docs). Pure:
// no I/O.
#pragma once

#include <cstddef>
#include <span>
#include <string>
#include <vector>

namespace brdf::uncertainty {

// One held-out reading, predicted from the others at its own pose.
struct HeldOutPoint {
  std::vector<double> residual;  // prediction − the reading, per band
  std::vector<double> spread;    // the prediction's vertices' spread s, per band
  std::vector<double> noise;     // the residual's standard uncertainty from the readings' own
                                 // independent noise, per band (empty: none known)
  double cell_size = 0;          // the prediction's cell size h (CellSize), for size bins
};

// What a cell larger than every held-out reading's gets.
enum class SizeBeyond {
  kGrow,          // the largest bin's c · h / h_max: a smooth BRDF's error grows as h², s as h
  kNotEstimated,  // no scale: the term is not estimated there (ScaleAt returns null)
};

// The cells from `above` (exclusive) on get `scale` (c per band).
struct SizeBin {
  double above = 0;
  std::vector<double> scale;
};

// The fitted scale c per band; empty `scale`: not calibrated (`detail` says why).
struct InterpolationCalibration {
  std::vector<double> scale;  // c(λ), per band
  std::size_t held_out = 0;   // held-out readings it rests on
  // Contiguous groups of bands with one c each: group g holds bands [g·n/groups, (g+1)·n/groups)
  // of n (BandGroupFirst); 0 when not calibrated.
  std::size_t band_groups = 0;
  std::string detail;  // how it was fitted, or why it was not
  // With size bins: `scale` is the smallest cells' c, `larger` the further bins' in ascending
  // order of `above`; `largest_cell` the largest held-out cell, beyond which `beyond` holds.
  // Empty `larger` and largest_cell 0: one c for every cell size.
  std::vector<SizeBin> larger;
  double largest_cell = 0;
  SizeBeyond beyond = SizeBeyond::kGrow;
};

// What the fit aims at.
struct CalibrationTarget {
  double k = 2;                // coverage factor of the intervals it calibrates
  double coverage = 0.95;      // fraction of held-out (reading, band) pairs inside k · u
  int band_groups = 4;         // contiguous groups of bands, one c each (at most one per band)
  std::size_t min_points = 8;  // fewer held-out readings: not calibrated
  // Bins of the held-out readings' cell sizes, one c each (fewer when a bin would hold fewer
  // than min_points readings); 1: one c for every cell size, and no SizeBeyond.
  int size_bins = 1;
  SizeBeyond beyond = SizeBeyond::kGrow;
};

// A pair needing a larger c than this has a spread that is rounding beside its residual: it counts
// as s = 0 (the vertices' spread explains nothing of it). On the simulator's sessions c is 0.5–4.
inline constexpr double kMaxNeededScale = 1e6;

// The quantile of the needs whose ratio between a size bin and the pooled held-out readings
// scales the pooled c into the bin's (robust to a bin's few pairs with a spread of nothing).
inline constexpr double kSizeBinQuantile = 0.9;

// Per band group, the smallest c such that |r| ≤ k · sqrt(noise² + (c · s)²) holds
// for the ⌈(n + 1) · coverage⌉-th smallest of the group's n held-out (reading, band) pairs' needs
// (all of them when that rank passes n). A pair the noise alone covers needs c = 0; a pair with s =
// 0 (or a need above kMaxNeededScale) that the noise does not cover needs more than any c: when the
// rank falls on such a pair, c is the largest finite need. With target.size_bins > 1 (and at
// least min_points readings a bin) that pooled c is scaled per size bin by the ratio of the bin's
// kSizeBinQuantile need to the pooled one, never below a smaller bin's. Points whose vectors do
// not have `bands` values are left out.
InterpolationCalibration FitInterpolationCalibration(std::span<const HeldOutPoint> points,
                                                     int bands, const CalibrationTarget& target);

// The first band of group `g` of `groups` over `bands` bands (g = groups: one past the last band).
inline std::size_t BandGroupFirst(std::size_t g, std::size_t groups, std::size_t bands) {
  return groups == 0 ? 0 : g * bands / groups;
}

// The factor a cell of size `cell_size` multiplies the spread by in band `band`: its size bin's c,
// times h / h_max beyond the largest held-out cell with SizeBeyond::kGrow. NaN beyond it with
// kNotEstimated, and when not calibrated.
double ScaleAt(const InterpolationCalibration& calibration, double cell_size, std::size_t band);

// Whether a cell of `cell_size` lies beyond the calibration's largest held-out cell with
// SizeBeyond::kNotEstimated (its term is not estimated).
bool BeyondCalibration(const InterpolationCalibration& calibration, double cell_size);

// Scales `spread` (s per band) in place into c(λ) · s(λ), c for a cell of `cell_size` (ScaleAt;
// one c for every size without size bins). False, leaving it unchanged, when `calibration` has no
// scale for its bands (not calibrated) or the cell lies beyond it (BeyondCalibration).
bool ApplyInterpolationCalibration(const InterpolationCalibration& calibration,
                                   std::span<double> spread, double cell_size = 0);

}  // namespace brdf::uncertainty
