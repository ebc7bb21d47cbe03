// Everything about talking to one Konica Minolta CS-2000 / CS-2000A / CS-3000 that an operator or
// a test may change: the port, the timeouts, the internal ND filter, the sync frequency and the
// quality policy. Defaults follow docs/cs2000-protocol.md; tests shrink the waits to run fast.
#pragma once

#include <chrono>
#include <string>

#include "core/status.h"
#include "drivers/cs2000/protocol.h"
#include "drivers/pr650/quality_codes.h"
#include "drivers/serial/serial_link.h"

namespace brdf::drivers {

struct Cs2000Options {
  using Millis = std::chrono::milliseconds;

  std::string port;  // RS-232C ("/dev/ttyUSB0") or the USB port ("/dev/ttyACM0")
  int baud = 9600;   // RS-232C: as set on the meter; ignored by a USB virtual port
  bool hardware_flow_control = false;
  std::string model = "CS-2000";  // what the configuration says it is, until IDDR tells

  cs2000::NdFilter nd_filter = cs2000::NdFilter::kAuto;  // SPMS's internal ND setting
  double sync_frequency_hz = 100;  // SCMS,1 when a plan asks for sync (100 Hz: 50 Hz mains)

  Millis command_pacing{50};   // pause after an exchange before the next command
  Millis quiet_gap{30};        // silence that ends a complete reply
  Millis stall_timeout{1000};  // silence that ends an incomplete reply (truncated)
  Millis reply_timeout{2000};  // first byte of an ordinary reply
  // MEAS,1's first reply (the measuring time) may take this long: the meter makes a
  // pre-measurement first (specio waits 10 s for it).
  Millis measure_start_timeout{10000};
  // The margin the completion reply gets on top of the measuring time the meter announced.
  Millis measurement_timeout{30000};
  int remote_attempts = 2;  // RMTS,1 tries before giving up

  int max_measure_attempts = 4;  // measurements per Measure call, retries included
  // Keyed by the PR-650's quality codes: cs2000::PolicyCodeFor maps each ERxx onto one.
  pr650::QualityPolicy quality_policy = pr650::QualityPolicy::Defaults();
  serial::LogSink log;  // empty: stderr
};

// kConfigurationError naming the first bad option and its allowed range.
Status ValidateCs2000Options(const Cs2000Options& options);

}  // namespace brdf::drivers
