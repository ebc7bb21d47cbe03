// Everything about talking to one PR-650 that an operator or a test may change: the port, the
// link timing, the wake-up sequence and the quality policy. Defaults follow
// docs/pr650.md; tests shrink the waits to run fast.
#pragma once

#include <chrono>
#include <string>

#include "core/status.h"
#include "drivers/pr650/quality_codes.h"
#include "drivers/serial/serial_link.h"

namespace brdf::drivers {

struct Pr650Options {
  using Millis = std::chrono::milliseconds;

  std::string port;  // "/dev/ttyUSB0", "/dev/serial/by-id/...", a pty link
  int baud = 9600;
  bool hardware_flow_control = false;

  Millis command_pacing{100};  // pause after an exchange before the next command is written
  Millis quiet_gap{50};        // silence that ends a complete reply
  Millis stall_timeout{1000};  // silence that ends an incomplete reply (truncated)
  Millis reply_timeout{2000};  // first byte of a short reply (B, D110, D120, D5)
  // The reply to S and F, and the margin a measurement (M0, M5) gets on top of its integration:
  // MeasurementReplyTimeout below.
  Millis measurement_timeout{30000};
  // The longest integration the meter may choose in adaptive mode (the PR-650's range ends at
  // 6,000 ms); a measurement's timeout counts adaptive integration at this.
  Millis adaptive_integration_max{6000};

  // Remote-mode entry: RTS dropped for rts_drop (> 50 ms) by close/reopen, raised again, then
  // wake_settle before the first command (B<wake_backlight>), repeated up to wake_attempts times
  // while the meter is silent. The sources quote the manual's "> 0.5 s" for that wait; one waits
  // 1 s, the default here ([meter] rts_settle_ms).
  Millis rts_drop{100};
  Millis wake_settle{1000};
  int wake_attempts = 5;
  int wake_backlight = 3;  // B3 (0–3)

  int accessory = 1;  // S field 1: 01 = the standard MS-75 lens

  // A reading in one exchange: M5 (measure, then send the D5 report) instead of M0 then D5. Saves
  // a command, a status reply and a quiet gap per reading; false for a meter that mishandles M5.
  bool measure_with_spectrum = true;

  // Measurements per Measure call, including the quality policy's retries.
  int max_measure_attempts = 4;
  pr650::QualityPolicy quality_policy = pr650::QualityPolicy::Defaults();

  // Diagnostics (tolerated pty limitations, retries, adaptations). Empty: written to stderr.
  serial::LogSink log;
};

// kConfigurationError naming the first bad option and its allowed range.
Status ValidatePr650Options(const Pr650Options& options);

// How long the meter may take to answer a measurement (M0, M5) with this setup: averages ×
// integration time (adaptive, 0: options.adaptive_integration_max) plus
// options.measurement_timeout as the margin for the meter's own work. 99 averages of 6,000 ms
// with the default margin: 624 s.
std::chrono::milliseconds MeasurementReplyTimeout(const Pr650Options& options, int integration_ms,
                                                  int averages);

}  // namespace brdf::drivers
