#include "drivers/pr650/options.h"

#include <algorithm>

namespace brdf::drivers {

namespace {

Status Bad(const std::string& what) {
  return ConfigurationError("PR-650 option " + what + ": fix the meter's configuration");
}

bool InRange(std::chrono::milliseconds d, long long lo_ms, long long hi_ms) {
  return d.count() >= lo_ms && d.count() <= hi_ms;
}

}  // namespace

Status ValidatePr650Options(const Pr650Options& o) {
  if (o.port.empty()) return Bad("port is empty (e.g. /dev/ttyUSB0)");
  if (!serial::IsSupportedBaud(o.baud)) {
    return Bad("baud " + std::to_string(o.baud) + " is not a supported rate (the meter uses 9600)");
  }
  if (!InRange(o.command_pacing, 0, 10'000)) return Bad("command_pacing must be 0–10000 ms");
  if (!InRange(o.quiet_gap, 1, 5'000)) return Bad("quiet_gap must be 1–5000 ms");
  if (!InRange(o.stall_timeout, 1, 60'000) || o.stall_timeout < o.quiet_gap) {
    return Bad("stall_timeout must be 1–60000 ms and not shorter than quiet_gap");
  }
  if (!InRange(o.reply_timeout, 1, 60'000)) return Bad("reply_timeout must be 1–60000 ms");
  if (!InRange(o.measurement_timeout, 1, 600'000)) {
    return Bad("measurement_timeout must be 1–600000 ms");
  }
  if (!InRange(o.adaptive_integration_max, 1, 60'000)) {
    return Bad("adaptive_integration_max must be 1–60000 ms (the PR-650's is 6000 ms)");
  }
  if (!InRange(o.rts_drop, 0, 10'000))
    return Bad("rts_drop must be 0–10000 ms (> 50 ms on a meter)");
  if (!InRange(o.wake_settle, 0, 10'000)) return Bad("wake_settle must be 0–10000 ms");
  if (o.wake_attempts < 1 || o.wake_attempts > 50) return Bad("wake_attempts must be 1–50");
  if (o.wake_backlight < 0 || o.wake_backlight > 3)
    return Bad("wake_backlight must be 0–3 (B0–B3)");
  if (o.accessory < 1 || o.accessory > 12) return Bad("accessory must be 1–12 (1 = MS-75 lens)");
  if (o.max_measure_attempts < 1 || o.max_measure_attempts > 50) {
    return Bad("max_measure_attempts must be 1–50");
  }
  return Status::Ok();
}

std::chrono::milliseconds MeasurementReplyTimeout(const Pr650Options& options, int integration_ms,
                                                  int averages) {
  const std::chrono::milliseconds integration = integration_ms > 0
                                                    ? std::chrono::milliseconds(integration_ms)
                                                    : options.adaptive_integration_max;
  return options.measurement_timeout + integration * std::max(1, averages);
}

}  // namespace brdf::drivers
