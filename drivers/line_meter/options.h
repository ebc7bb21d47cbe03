// What every meter driven in lines over a serial::CommandChannel (the PR-655/PR-670, the
// CS-2000/CS-3000) lets an operator or a test change: the port, the pacing and timeouts of its
// exchanges, the remote-mode attempts and the quality policy. Each meter's options add its own
// (drivers/pr670/options.h, drivers/cs2000/options.h) and set the defaults its manual calls for.
#pragma once

#include <chrono>
#include <string>
#include <string_view>

#include "core/status.h"
#include "drivers/pr650/quality_codes.h"
#include "drivers/serial/serial_link.h"

namespace brdf::drivers {

struct LineMeterOptions {
  using Millis = std::chrono::milliseconds;

  std::string port;  // the meter's port ("/dev/ttyACM0", "/dev/ttyUSB0", "/dev/serial/by-id/...")
  int baud = 9600;   // ignored by a USB virtual port; an RS-232 line must match the meter
  bool hardware_flow_control = false;
  std::string model;  // what the configuration says it is, until the meter tells

  Millis command_pacing{100};  // pause after an exchange before the next command
  Millis quiet_gap{50};        // silence that ends a complete reply
  Millis stall_timeout{1000};  // silence that ends an incomplete reply (truncated)
  Millis reply_timeout{2000};  // first byte of an ordinary (short) reply
  // The margin a measurement's reply gets on top of the time the measurement itself takes.
  Millis measurement_timeout{30000};
  int remote_attempts = 2;  // tries of the remote-mode command before giving up

  int max_measure_attempts = 4;  // measurements per Measure call, retries included
  // Keyed by the PR-650's quality codes: each meter maps its own codes onto them.
  pr650::QualityPolicy quality_policy = pr650::QualityPolicy::Defaults();
  serial::LogSink log;  // empty: stderr
};

// kConfigurationError "<meter> option <what>: fix the meter's configuration".
Status LineMeterOptionError(std::string_view meter, const std::string& what);

// The first of the shared options outside its allowed range, as LineMeterOptionError; `meter`
// names the family ("PR-670"), `example_port` is its usual port.
Status ValidateLineMeterOptions(const LineMeterOptions& options, std::string_view meter,
                                std::string_view example_port);

// True if `d` is within [lo_ms, hi_ms].
bool InRangeMs(std::chrono::milliseconds d, long long lo_ms, long long hi_ms);

}  // namespace brdf::drivers
