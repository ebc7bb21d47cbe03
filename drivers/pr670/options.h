// Everything about talking to one PR-655 or PR-670 that an operator or a test may change: the
// port, the typing pace, the timeouts, the remote-mode entry and the quality policy. Defaults
// follow docs/pr670-protocol.md; tests shrink the waits to run fast.
#pragma once

#include <chrono>
#include <string>

#include "core/status.h"
#include "drivers/pr650/quality_codes.h"
#include "drivers/serial/serial_link.h"

namespace brdf::drivers {

struct Pr670Options {
  using Millis = std::chrono::milliseconds;

  std::string port;  // the meter's USB CDC port ("/dev/ttyACM0", "/dev/serial/by-id/...")
  int baud = 9600;   // ignored by a USB CDC port; an RS-232 adapter must match the meter
  bool hardware_flow_control = false;
  std::string model = "PR-670";  // what the configuration says it is, until D111 tells

  // Commands are typed a character at a time, this far apart (Psychtoolbox's PR670write waits
  // 50 ms after each character; PsychoPy's PR655 writes one character per write too).
  Millis char_gap{50};
  Millis command_pacing{100};  // pause after an exchange before the next command
  Millis quiet_gap{50};        // silence that ends a complete reply
  Millis stall_timeout{1000};  // silence that ends an incomplete reply (truncated)
  Millis reply_timeout{2000};  // first byte of a short reply (D110, D111, D120, S…)
  // Remote-mode entry: Q, then quit_settle, then PHOTO; the meter's answer within
  // remote_timeout (both open drivers wait up to 10 s), up to remote_attempts times.
  Millis quit_settle{500};
  Millis remote_timeout{10000};
  int remote_attempts = 2;
  // The margin a measurement (M5) gets on top of averages × exposure (adaptive: the longest
  // exposure the meter may choose, adaptive_exposure_max).
  Millis measurement_timeout{30000};
  Millis adaptive_exposure_max{30000};

  int max_measure_attempts = 4;  // measurements per Measure call, retries included
  // Keyed by the PR-650's quality codes: pr670::PolicyCodeFor maps each PR-670 code onto one.
  pr650::QualityPolicy quality_policy = pr650::QualityPolicy::Defaults();
  serial::LogSink log;  // empty: stderr
};

// kConfigurationError naming the first bad option and its allowed range.
Status ValidatePr670Options(const Pr670Options& options);

// How long an M5 may take: averages × exposure (0: adaptive_exposure_max) plus the margin.
std::chrono::milliseconds Pr670MeasurementTimeout(const Pr670Options& options, int exposure_ms,
                                                  int averages);

}  // namespace brdf::drivers
