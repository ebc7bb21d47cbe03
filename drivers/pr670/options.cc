#include "drivers/pr670/options.h"

#include <algorithm>

namespace brdf::drivers {

namespace {

Status Bad(const std::string& what) {
  return ConfigurationError("PR-670 option " + what + ": fix the meter's configuration");
}

bool InRange(std::chrono::milliseconds d, long long lo_ms, long long hi_ms) {
  return d.count() >= lo_ms && d.count() <= hi_ms;
}

}  // namespace

Status ValidatePr670Options(const Pr670Options& o) {
  if (o.port.empty()) return Bad("port is empty (e.g. /dev/ttyACM0)");
  if (!serial::IsSupportedBaud(o.baud)) {
    return Bad("baud " + std::to_string(o.baud) + " is not a standard rate 1200–115200");
  }
  if (!InRange(o.char_gap, 0, 1'000)) return Bad("char_gap must be 0–1000 ms");
  if (!InRange(o.command_pacing, 0, 10'000)) return Bad("command_pacing must be 0–10000 ms");
  if (!InRange(o.quiet_gap, 1, 5'000)) return Bad("quiet_gap must be 1–5000 ms");
  if (!InRange(o.stall_timeout, 1, 60'000) || o.stall_timeout < o.quiet_gap) {
    return Bad("stall_timeout must be 1–60000 ms and not shorter than quiet_gap");
  }
  if (!InRange(o.reply_timeout, 1, 60'000)) return Bad("reply_timeout must be 1–60000 ms");
  if (!InRange(o.quit_settle, 0, 10'000)) return Bad("quit_settle must be 0–10000 ms");
  if (!InRange(o.remote_timeout, 1, 60'000)) return Bad("remote_timeout must be 1–60000 ms");
  if (o.remote_attempts < 1 || o.remote_attempts > 20) return Bad("remote_attempts must be 1–20");
  if (!InRange(o.measurement_timeout, 1, 600'000)) {
    return Bad("measurement_timeout must be 1–600000 ms");
  }
  if (!InRange(o.adaptive_exposure_max, 1, 600'000)) {
    return Bad("adaptive_exposure_max must be 1–600000 ms");
  }
  if (o.max_measure_attempts < 1 || o.max_measure_attempts > 50) {
    return Bad("max_measure_attempts must be 1–50");
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
