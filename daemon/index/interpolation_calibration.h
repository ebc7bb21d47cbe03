// The interpolation term's calibration for one index snapshot (docs/uncertainty.md, "The
// interpolation term"; the fit is core/uncertainty/interpolation_calibration.h): readings held
// out of the index in folds chosen by a hash of their ids (deterministic), each fold predicted
// by an index of the same method and options over the others, their residuals fitted.
//
// Bounded: at most kMaxHeldOut readings are predicted, in at most kMaxFolds folds, and the folds'
// indexes together hold at most about kMaxFoldSamples* readings: a small session is left out a
// reading or a few at a time (nearly leave-one-out, every reading predicted), a large one in one or
// two folds of at most kMaxHeldOut/folds readings (one index build over the rest each). Computed
// on the snapshot's first answer with uncertainty (CalibrationSlot), never by a build or by
// answers without uncertainty.
#pragma once

#include <cstddef>
#include <memory>
#include <mutex>
#include <vector>

#include "core/interp/interpolator.h"
#include "core/uncertainty/interpolation_calibration.h"
#include "daemon/index/budgets.h"

namespace brdf::daemon {

struct IndexSnapshot;

inline constexpr std::size_t kMaxHeldOut = 300;
inline constexpr std::size_t kMaxFolds = 32;
// Readings the folds' indexes may hold together: a tree build (octant) costs about 2 µs a
// reading, Qhull's (Delaunay) about 15–40 (bench/uncertainty/calibration_cost.cc).
inline constexpr std::size_t kMaxFoldSamplesOctant = 60000;
inline constexpr std::size_t kMaxFoldSamplesOther = 10000;

// The held-out predictions over `samples` by `method` with `options`: for each fold, an index
// over the samples outside it, evaluated at each held-out sample's pose; answers that are not OK
// are left out. `budgets` (position for position; may be empty) give each point's noise: the
// held-out reading's independent part and its vertices' (weighted) in quadrature.
std::vector<uncertainty::HeldOutPoint> PredictHeldOut(const interp::SampleSet& samples,
                                                      const BudgetList& budgets,
                                                      interp::Method method,
                                                      const interp::Options& options);

// The snapshot's calibration: not calibrated (detail says why) for the nearest method, which has
// no interpolation term, and when too few held-out readings could be predicted.
uncertainty::InterpolationCalibration CalibrateInterpolation(const IndexSnapshot& snapshot);

// Holds a snapshot's calibration, computed once on first use; thread-safe. A recording session's
// next snapshots share their predecessor's slot until the session has grown by a quarter
// (CarriedCalibration): the calibration is a property of the sample and the grid's density, which
// a few more readings barely change, and each calibration builds up to kMaxFolds indexes.
class CalibrationSlot {
 public:
  CalibrationSlot() = default;
  // `samples`: how many samples the snapshot it was made for holds.
  explicit CalibrationSlot(std::size_t samples) : samples_(samples) {}
  std::size_t samples() const { return samples_; }
  const uncertainty::InterpolationCalibration& Get(const IndexSnapshot& snapshot) const {
    std::call_once(once_, [&] { value_ = CalibrateInterpolation(snapshot); });
    return value_;
  }

 private:
  std::size_t samples_ = 0;
  mutable std::once_flag once_;
  mutable uncertainty::InterpolationCalibration value_;
};

// The calibration slot of a new snapshot over `samples` samples: `previous`'s (this key's
// snapshot over fewer readings, may be null) while samples ≤ 1.25 × the samples its slot was made
// for, else a new one.
std::shared_ptr<const CalibrationSlot> CarriedCalibration(const IndexSnapshot* previous,
                                                          std::size_t samples);

}  // namespace brdf::daemon
