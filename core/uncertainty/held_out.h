// The interpolation term's calibration from a session's own readings (docs/uncertainty.md, "The
// interpolation term"; the fit is interpolation_calibration.h): readings held out of the index in
// folds chosen by a hash of their ids (deterministic), each fold predicted by an index of the same
// method and options over the others, their residuals fitted. The same for the API's index
// snapshots (daemon/index/interpolation_calibration.h) and the exports' interpolants
// (core/export/fill/uncertain_chain.h), so that both calibrate the same session alike.
//
// Bounded: at most kMaxHeldOut readings are predicted, in at most kMaxFolds folds, and the folds'
// indexes together hold at most about kMaxFoldSamples* readings: a small session is left out a
// reading or a few at a time (nearly leave-one-out, every reading predicted), a large one in one or
// two folds of at most kMaxHeldOut/folds readings (one index build over the rest each). Pure: no
// I/O.
#pragma once

#include <atomic>
#include <cstddef>
#include <functional>
#include <mutex>
#include <vector>

#include "core/interp/interpolator.h"
#include "core/uncertainty/budget.h"
#include "core/uncertainty/interpolation_calibration.h"

namespace brdf::uncertainty {

inline constexpr std::size_t kMaxHeldOut = 300;
inline constexpr std::size_t kMaxFolds = 32;
// Readings the folds' indexes may hold together: a tree build (octant) costs about 2 µs a
// reading, Qhull's (Delaunay) about 15–40 (bench/uncertainty/calibration_cost.cc).
inline constexpr std::size_t kMaxFoldSamplesOctant = 60000;
inline constexpr std::size_t kMaxFoldSamplesOther = 10000;

// Sample i's independent part (its budget's, a value per band: ReadingBudget::independent,
// BlendBudget::independent), by its position in the sample set, or null when it has none: all
// the held-out points' noise reads of a budget. Unset: no sample has one.
using IndependentOf = std::function<const std::vector<double>*(std::size_t index)>;

// The samples' positions in the order the folds take them: by a fixed hash of their ids (the
// folds do not follow the plan's order; the same session gives the same folds).
std::vector<std::size_t> HeldOutOrder(const interp::SampleSet& samples);

// The held-out predictions over `samples` by `method` with `options`: for each fold, an index
// over the samples outside it, evaluated at each held-out sample's pose; answers that are not OK
// are left out. `independent_of` gives each point's noise: the held-out reading's independent part
// and its vertices' (weighted) in quadrature; a point whose reading has none has none.
std::vector<HeldOutPoint> PredictHeldOut(const interp::SampleSet& samples,
                                         const IndependentOf& independent_of, interp::Method method,
                                         const interp::Options& options);

// Delaunay's held-out readings binned by their cell's size (interpolation_calibration.h): its
// simplices span the data's gaps, and a large one errs more, relative to its vertices' spread,
// than a small one (docs/uncertainty.md, "Coverage of the export's cells"). The octant method's
// cells are bounded by their octants, and it predicts too few held-out readings to bin.
inline constexpr int kDelaunaySizeBins = 3;

// What `method`'s calibration aims at: CalibrationTarget's defaults, with kDelaunaySizeBins size
// bins for Delaunay (a cell larger than every held-out one: c grows with its size).
CalibrationTarget TargetOf(interp::Method method);

// The calibration of the interpolation term of `method` over `samples` (`bands` values a
// spectrum; `independent_of` as PredictHeldOut's), aimed as TargetOf(method): not calibrated
// (detail says why) for the nearest method, which has no interpolation term, and when fewer
// held-out readings than CalibrationTarget::min_points could be predicted.
InterpolationCalibration CalibrateInterpolation(const interp::SampleSet& samples,
                                                const IndependentOf& independent_of,
                                                interp::Method method,
                                                const interp::Options& options, int bands);

// A calibration computed once, on first use, and kept (an index snapshot's, an export
// interpolant's); thread-safe: concurrent first users wait for the one computing it.
class CalibrationOnce {
 public:
  // The calibration, `compute`d by the first caller.
  const InterpolationCalibration& Get(
      const std::function<InterpolationCalibration()>& compute) const {
    std::call_once(once_, [&] {
      value_ = compute();
      computed_.store(true, std::memory_order_release);
    });
    return value_;
  }
  // Whether a Get has computed it.
  bool computed() const { return computed_.load(std::memory_order_acquire); }

 private:
  mutable std::once_flag once_;
  mutable InterpolationCalibration value_;
  mutable std::atomic<bool> computed_{false};
};

}  // namespace brdf::uncertainty
