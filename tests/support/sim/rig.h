// The simulator rig the process tests stand on: brdf-sim started for a fast, deterministic run
// (simulated time kSimTimeScale× faster, no 9600-baud pacing, no wake window, Modbus on a free
// port) and the test's hand on its control unit (what is mounted, the meter's power, faults).
// brdfd then drives it through the real drivers (tests/support/daemon/test_rig.h,
// tests/brdfctl/ctl_test_rig.h). Tests that need instruments but not their wire protocols use
// the in-process fakes instead (tests/support/fakes/rig.h).
#pragma once

#include <memory>
#include <string>
#include <vector>

#include "core/status.h"
#include "tests/support/sim/modbus_control.h"
#include "tests/support/sim/process.h"

namespace brdf::testing {

inline constexpr double kSimTimeScale = 50;

// brdf-sim's flags for that run with the simulator's random seed `seed`, then `extra`.
std::vector<std::string> FastSimArgs(int seed, const std::vector<std::string>& extra = {});

struct SimRig {
  std::unique_ptr<SimProcess> sim;
  std::unique_ptr<ModbusControl> control;

  // "host:port" of brdf-sim's Modbus TCP server.
  std::string modbus_address() const;
};

// Starts brdf-sim with FastSimArgs(seed, extra) and connects to its control unit.
Result<SimRig> StartSimRig(int seed, const std::vector<std::string>& extra = {});

}  // namespace brdf::testing
