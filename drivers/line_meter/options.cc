#include "drivers/line_meter/options.h"

namespace brdf::drivers {

Status LineMeterOptionError(std::string_view meter, const std::string& what) {
  return ConfigurationError(std::string(meter) + " option " + what +
                            ": fix the meter's configuration");
}

bool InRangeMs(std::chrono::milliseconds d, long long lo_ms, long long hi_ms) {
  return d.count() >= lo_ms && d.count() <= hi_ms;
}

Status ValidateLineMeterOptions(const LineMeterOptions& o, std::string_view meter,
                                std::string_view example_port) {
  auto bad = [meter](const std::string& what) { return LineMeterOptionError(meter, what); };
  if (o.port.empty()) return bad("port is empty (e.g. " + std::string(example_port) + ")");
  if (!serial::IsSupportedBaud(o.baud)) {
    return bad("baud " + std::to_string(o.baud) + " is not a standard rate 1200–115200");
  }
  if (!InRangeMs(o.command_pacing, 0, 10'000)) return bad("command_pacing must be 0–10000 ms");
  if (!InRangeMs(o.quiet_gap, 1, 5'000)) return bad("quiet_gap must be 1–5000 ms");
  if (!InRangeMs(o.stall_timeout, 1, 60'000) || o.stall_timeout < o.quiet_gap) {
    return bad("stall_timeout must be 1–60000 ms and not shorter than quiet_gap");
  }
  if (!InRangeMs(o.reply_timeout, 1, 60'000)) return bad("reply_timeout must be 1–60000 ms");
  if (!InRangeMs(o.measurement_timeout, 1, 600'000)) {
    return bad("measurement_timeout must be 1–600000 ms");
  }
  if (o.remote_attempts < 1 || o.remote_attempts > 20) return bad("remote_attempts must be 1–20");
  if (o.max_measure_attempts < 1 || o.max_measure_attempts > 50) {
    return bad("max_measure_attempts must be 1–50");
  }
  return Status::Ok();
}

}  // namespace brdf::drivers
