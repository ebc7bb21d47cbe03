// A daemon::Rig on the in-process fake devices (tests/support/fakes/devices.h), for tests of the
// executor and the session manager that need instruments but not their wire protocols: no
// brdf-sim process, no serial line, no Modbus. The test keeps the bench (what is mounted, the
// pose) and each device's fault switch; the rig owns the fakes.
#pragma once

#include <memory>

#include "core/plan/rig_description.h"
#include "daemon/engine/rig.h"
#include "tests/support/fakes/devices.h"

namespace brdf::testing {

// The rig as brdf-sim builds it by default: α/β plus a motorized detector arm (δ), γ as a dial.
plan::RigDescription SimRigDescription();

// Short connection back-offs and a quick live-pose poll, for tests.
daemon::Rig::Options FastRigOptions();

struct FakeRig {
  std::shared_ptr<FakeBench> bench;
  std::shared_ptr<FakeFaultSwitch> meter_faults;
  std::shared_ptr<FakeFaultSwitch> stage_faults;
  std::shared_ptr<daemon::Rig> rig;
};

// A fake meter and a fake stage with the axes and travel of `description`, in a Rig built with
// `options`; simulated time runs `time_scale` times faster (as brdf-sim's --time-scale).
FakeRig MakeFakeRig(const plan::RigDescription& description = SimRigDescription(),
                    daemon::Rig::Options options = FastRigOptions(), double time_scale = 50);

}  // namespace brdf::testing
