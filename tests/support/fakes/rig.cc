#include "tests/support/fakes/rig.h"

namespace brdf::testing {

using namespace std::chrono_literals;

plan::RigDescription SimRigDescription() {
  plan::RigDescription rig;
  rig.has_detector_arm = true;
  rig.has_gamma_axis = false;
  rig.alpha = {0, 90, 30};
  rig.beta = {-180, 180, 30};
  rig.gamma = {-180, 180, 30};
  rig.delta = {0, 180, 30};
  rig.meter_transfer_s = 0.05;
  rig.operator_action_s = 1;
  return rig;
}

daemon::Rig::Options FastRigOptions() {
  daemon::Rig::Options options;
  options.backoff_initial = 50ms;
  options.backoff_max = 500ms;
  options.connect_timeout = 3000ms;
  options.pose_poll_interval = 100ms;
  return options;
}

FakeRig MakeFakeRig(const plan::RigDescription& description, daemon::Rig::Options options,
                    double time_scale) {
  FakeRig fake;
  fake.bench = std::make_shared<FakeBench>();
  fake.meter_faults = std::make_shared<FakeFaultSwitch>();
  fake.stage_faults = std::make_shared<FakeFaultSwitch>();
  FakeMeterOptions meter;
  meter.time_scale = time_scale;
  meter.convention = description.convention;
  FakeStageOptions stage;
  stage.has_gamma = description.has_gamma_axis;
  stage.has_delta = description.has_detector_arm;
  stage.time_scale = time_scale;
  const plan::AxisTravel* travel[] = {&description.alpha, &description.beta, &description.gamma,
                                      &description.delta};
  for (int i = 0; i < 4; ++i) {
    stage.min_deg[i] = travel[i]->min_deg;
    stage.max_deg[i] = travel[i]->max_deg;
  }
  stage.speed_deg_s = description.alpha.speed_deg_s;
  fake.rig = std::make_shared<daemon::Rig>(
      std::make_unique<FakeMeter>(fake.bench, fake.meter_faults, meter),
      daemon::Rig::DeviceInfo{"PR-650 (fake)", "in-process"},
      std::make_unique<FakeStage>(fake.bench, fake.stage_faults, stage),
      daemon::Rig::DeviceInfo{"stage (fake)", "in-process"}, description, options);
  return fake;
}

}  // namespace brdf::testing
