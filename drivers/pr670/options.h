// Everything about talking to one PR-655 or PR-670 that an operator or a test may change: the
// port, the typing pace, the timeouts, the remote-mode entry and the quality policy. Defaults
// follow docs/pr670-protocol.md; tests shrink the waits to run fast.
#pragma once

#include <chrono>

#include "core/status.h"
#include "drivers/line_meter/options.h"

namespace brdf::drivers {

struct Pr670Options : LineMeterOptions {
  Pr670Options() { model = "PR-670"; }

  // Commands are typed a character at a time, this far apart (Psychtoolbox's PR670write waits
  // 50 ms after each character; PsychoPy's PR655 writes one character per write too).
  Millis char_gap{50};
  // Remote-mode entry: Q, then quit_settle, then PHOTO; the meter's answer within
  // remote_timeout (both open drivers wait up to 10 s), up to remote_attempts times.
  Millis quit_settle{500};
  Millis remote_timeout{10000};
  // A measurement (M5) gets measurement_timeout on top of averages × exposure (adaptive: the
  // longest exposure the meter may choose, adaptive_exposure_max).
  Millis adaptive_exposure_max{30000};
};

// kConfigurationError naming the first bad option and its allowed range.
Status ValidatePr670Options(const Pr670Options& options);

// How long an M5 may take: averages × exposure (0: adaptive_exposure_max) plus the margin.
std::chrono::milliseconds Pr670MeasurementTimeout(const Pr670Options& options, int exposure_ms,
                                                  int averages);

}  // namespace brdf::drivers
