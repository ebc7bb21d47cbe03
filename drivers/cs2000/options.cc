#include "drivers/cs2000/options.h"

namespace brdf::drivers {

namespace {

Status Bad(const std::string& what) {
  return ConfigurationError("CS-2000 option " + what + ": fix the meter's configuration");
}

bool InRange(std::chrono::milliseconds d, long long lo_ms, long long hi_ms) {
  return d.count() >= lo_ms && d.count() <= hi_ms;
}

}  // namespace

Status ValidateCs2000Options(const Cs2000Options& o) {
  if (o.port.empty()) return Bad("port is empty (e.g. /dev/ttyUSB0)");
  if (!serial::IsSupportedBaud(o.baud)) {
    return Bad("baud " + std::to_string(o.baud) + " is not a standard rate 1200–115200");
  }
  if (!(o.sync_frequency_hz >= 20 && o.sync_frequency_hz <= 200)) {
    return Bad("sync_frequency_hz must be 20–200 Hz");
  }
  if (!InRange(o.command_pacing, 0, 10'000)) return Bad("command_pacing must be 0–10000 ms");
  if (!InRange(o.quiet_gap, 1, 5'000)) return Bad("quiet_gap must be 1–5000 ms");
  if (!InRange(o.stall_timeout, 1, 60'000) || o.stall_timeout < o.quiet_gap) {
    return Bad("stall_timeout must be 1–60000 ms and not shorter than quiet_gap");
  }
  if (!InRange(o.reply_timeout, 1, 60'000)) return Bad("reply_timeout must be 1–60000 ms");
  if (!InRange(o.measure_start_timeout, 1, 120'000)) {
    return Bad("measure_start_timeout must be 1–120000 ms");
  }
  if (!InRange(o.measurement_timeout, 1, 600'000)) {
    return Bad("measurement_timeout must be 1–600000 ms");
  }
  if (o.remote_attempts < 1 || o.remote_attempts > 20) return Bad("remote_attempts must be 1–20");
  if (o.max_measure_attempts < 1 || o.max_measure_attempts > 50) {
    return Bad("max_measure_attempts must be 1–50");
  }
  return Status::Ok();
}

}  // namespace brdf::drivers
