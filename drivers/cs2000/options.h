// Everything about talking to one Konica Minolta CS-2000 / CS-2000A / CS-3000 that an operator or
// a test may change: the port, the timeouts, the internal ND filter, the sync frequency and the
// quality policy. Defaults follow docs/cs2000-protocol.md; tests shrink the waits to run fast.
#pragma once

#include "core/status.h"
#include "drivers/cs2000/protocol.h"
#include "drivers/line_meter/options.h"

namespace brdf::drivers {

struct Cs2000Options : LineMeterOptions {
  Cs2000Options() {
    model = "CS-2000";
    command_pacing = Millis{50};
    quiet_gap = Millis{30};
  }

  cs2000::NdFilter nd_filter = cs2000::NdFilter::kAuto;  // SPMS's internal ND setting
  double sync_frequency_hz = 100;  // SCMS,1 when a plan asks for sync (100 Hz: 50 Hz mains)
  // MEAS,1's first reply (the measuring time) may take this long: the meter makes a
  // pre-measurement first (specio waits 10 s for it). The completion reply then gets
  // measurement_timeout on top of the measuring time the meter announced.
  Millis measure_start_timeout{10000};
};

// kConfigurationError naming the first bad option and its allowed range.
Status ValidateCs2000Options(const Cs2000Options& options);

}  // namespace brdf::drivers
