#include "drivers/pr670/options.h"

#include <algorithm>

namespace brdf::drivers {

Status ValidatePr670Options(const Pr670Options& o) {
  BRDF_RETURN_IF_ERROR(ValidateLineMeterOptions(o, "PR-670", "/dev/ttyACM0"));
  auto bad = [](const std::string& what) { return LineMeterOptionError("PR-670", what); };
  if (!InRangeMs(o.char_gap, 0, 1'000)) return bad("char_gap must be 0–1000 ms");
  if (!InRangeMs(o.quit_settle, 0, 10'000)) return bad("quit_settle must be 0–10000 ms");
  if (!InRangeMs(o.remote_timeout, 1, 60'000)) return bad("remote_timeout must be 1–60000 ms");
  if (!InRangeMs(o.adaptive_exposure_max, 1, 600'000)) {
    return bad("adaptive_exposure_max must be 1–600000 ms");
  }
  return Status::Ok();
}

std::chrono::milliseconds Pr670MeasurementTimeout(const Pr670Options& options, int exposure_ms,
                                                  int averages) {
  const std::chrono::milliseconds exposure =
      exposure_ms > 0 ? std::chrono::milliseconds(exposure_ms) : options.adaptive_exposure_max;
  return options.measurement_timeout + exposure * std::max(1, averages);
}

}  // namespace brdf::drivers
