// The interpolation term's calibration for one index snapshot (docs/uncertainty.md, "The
// interpolation term"): core/uncertainty/held_out.h's held-out predictions over the snapshot's
// samples and budgets, by its method and options. Computed on the snapshot's first answer with
// uncertainty (CalibrationSlot), never by a build or by answers without uncertainty.
#pragma once

#include <cstddef>
#include <memory>

#include "core/uncertainty/held_out.h"
#include "core/uncertainty/interpolation_calibration.h"

namespace brdf::daemon {

struct IndexSnapshot;

// The snapshot's calibration: not calibrated (detail says why) for the nearest method, which has
// no interpolation term, and when too few held-out readings could be predicted.
uncertainty::InterpolationCalibration CalibrateInterpolation(const IndexSnapshot& snapshot);

// Holds a snapshot's calibration, computed once on first use; thread-safe. A recording session's
// next snapshots share their predecessor's slot until the session has grown by a quarter
// (CarriedCalibration): the calibration is a property of the sample and the grid's density, which
// a few more readings barely change, and each calibration builds up to
// uncertainty::kMaxFolds indexes.
class CalibrationSlot {
 public:
  CalibrationSlot() = default;
  // `samples`: how many samples the snapshot it was made for holds.
  explicit CalibrationSlot(std::size_t samples) : samples_(samples) {}
  std::size_t samples() const { return samples_; }
  const uncertainty::InterpolationCalibration& Get(const IndexSnapshot& snapshot) const {
    return once_.Get([&] { return CalibrateInterpolation(snapshot); });
  }
  // Whether a Get has computed it.
  bool computed() const { return once_.computed(); }

 private:
  std::size_t samples_ = 0;
  uncertainty::CalibrationOnce once_;
};

// The calibration slot of a new snapshot over `samples` samples: `previous`'s (this key's
// snapshot over fewer readings, may be null) while samples ≤ 1.25 × the samples its slot was made
// for, else a new one.
std::shared_ptr<const CalibrationSlot> CarriedCalibration(const IndexSnapshot* previous,
                                                          std::size_t samples);

}  // namespace brdf::daemon
