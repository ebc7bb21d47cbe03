#include "daemon/index/interpolation_calibration.h"

#include <memory>

#include "daemon/index/cache.h"

namespace brdf::daemon {

uncertainty::InterpolationCalibration CalibrateInterpolation(const IndexSnapshot& snapshot) {
  if (!snapshot.samples) {
    uncertainty::InterpolationCalibration none;
    none.detail = "the snapshot has no samples";
    return none;
  }
  const BudgetList& budgets = snapshot.budgets;
  return uncertainty::CalibrateInterpolation(
      *snapshot.samples, [&budgets](std::size_t i) { return budgets.at(i); }, snapshot.method,
      snapshot.options, snapshot.grid.count);
}

std::shared_ptr<const CalibrationSlot> CarriedCalibration(const IndexSnapshot* previous,
                                                          std::size_t samples) {
  if (previous != nullptr && previous->calibration != nullptr) {
    const std::size_t base = previous->calibration->samples();
    if (samples <= base + base / 4) return previous->calibration;
  }
  return std::make_shared<CalibrationSlot>(samples);
}

}  // namespace brdf::daemon
