#include "daemon/index/interpolation_calibration.h"

#include <memory>
#include <vector>

#include "daemon/index/cache.h"

namespace brdf::daemon {

uncertainty::InterpolationCalibration CalibrateInterpolation(const IndexSnapshot& snapshot) {
  if (!snapshot.samples) {
    uncertainty::InterpolationCalibration none;
    none.detail = "the snapshot has no samples";
    return none;
  }
  const BudgetList& budgets = snapshot.budgets;
  const uncertainty::IndependentOf independent_of =
      [&budgets](std::size_t i) -> const std::vector<double>* {
    const uncertainty::BlendBudget* b = budgets.at(i);
    return b != nullptr ? &b->independent : nullptr;
  };
  return uncertainty::CalibrateInterpolation(*snapshot.samples, independent_of, snapshot.method,
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
