// Everything about talking to one PR-650 that an operator or a test may change: the port, the
// link timing, the wake-up sequence and the quality policy. Defaults follow
// docs/pr650.md; tests shrink the waits to run fast.
#pragma once

#include <chrono>
#include <string>

#include "core/status.h"
#include "drivers/pr650/quality_codes.h"
#include "drivers/pr650/serial_link.h"

namespace brdf::drivers {

struct Pr650Options {
  using Millis = std::chrono::milliseconds;

  std::string port;  // "/dev/ttyUSB0", "/dev/serial/by-id/...", a pty link
  int baud = 9600;
  bool hardware_flow_control = false;

  Millis command_pacing{100};         // pause after an exchange before the next command is written
  Millis quiet_gap{50};               // silence that ends a complete reply
  Millis stall_timeout{1000};         // silence that ends an incomplete reply (truncated)
  Millis reply_timeout{2000};         // first byte of a short reply (B, D110, D120, D5)
  Millis measurement_timeout{30000};  // reply to M0, S and F (integration time plus overhead)

  // Remote-mode entry: RTS dropped for rts_drop (> 50 ms) by close/reopen, wake_settle later the
  // first command (B<wake_backlight>), repeated up to wake_attempts times while the meter is
  // silent.
  Millis rts_drop{100};
  Millis wake_settle{500};
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
  pr650::LogSink log;
};

// kConfigurationError naming the first bad option and its allowed range.
Status ValidatePr650Options(const Pr650Options& options);

}  // namespace brdf::drivers
