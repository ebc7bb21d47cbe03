#include "tests/engine/engine_test_rig.h"

#include <gtest/gtest.h>

#include "core/plan/plan_json.h"
#include "drivers/pr650/pr650_spectroradiometer.h"
#include "drivers/stage/modbus_stage.h"

namespace brdf::testing {

using namespace std::chrono_literals;

std::vector<std::string> FastSimArgs(const std::vector<std::string>& extra) {
  std::vector<std::string> args = {"--time-scale",  std::to_string(kTimeScale),
                                   "--seed",        "7",
                                   "--modbus-port", "0",
                                   "--wake-window", "0",
                                   "--no-pacing",   "--log-level",
                                   "warn"};
  args.insert(args.end(), extra.begin(), extra.end());
  return args;
}

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

std::shared_ptr<daemon::Rig> MakeSimRig(const SimProcess& sim) {
  drivers::Pr650Options meter;
  meter.port = sim.pr650_path();
  meter.command_pacing = 5ms;
  meter.quiet_gap = 20ms;
  meter.stall_timeout = 300ms;
  meter.reply_timeout = 500ms;
  meter.measurement_timeout = 3000ms;
  meter.rts_drop = 5ms;
  meter.wake_settle = 10ms;
  meter.wake_attempts = 3;
  meter.log = [](std::string_view) {};
  // Dark readings are weak by nature: accept quality 10 flagged, as a lab taking darks
  // configures it ([meter.quality] "10" = "accept_and_flag").
  meter.quality_policy.Set(10, {drivers::pr650::QualityAction::kAcceptAndFlag, true});

  drivers::stage::ModbusStageConfig stage;
  drivers::stage::BusConfig bus;
  bus.endpoint = drivers::stage::TcpEndpoint{sim.modbus_host(), sim.modbus_port()};
  bus.response_timeout = 300ms;
  bus.reconnect_backoff = 10ms;
  bus.busy_backoff = 5ms;
  stage.buses = {bus};
  const plan::RigDescription rig = SimRigDescription();
  const plan::AxisTravel* travel[] = {&rig.alpha, &rig.beta, &rig.gamma, &rig.delta};
  for (int i = 0; i < 4; ++i) {
    drivers::stage::AxisConfig& a = stage.axes[static_cast<std::size_t>(i)];
    a.present = i != 2;  // γ is a dial on this rig
    a.bus = 0;
    a.unit_id = i + 1;
    a.min_deg = travel[i]->min_deg;
    a.max_deg = travel[i]->max_deg;
    a.speed_deg_s = travel[i]->speed_deg_s;
  }
  stage.poll_interval = 5ms;
  stage.pulse_hold = 5ms;
  stage.start_grace = 100ms;
  auto created = drivers::stage::ModbusStage::Create(stage);
  EXPECT_TRUE(created.ok()) << created.status().ToString();
  if (!created.ok()) return nullptr;

  daemon::Rig::Options options;
  options.backoff_initial = 50ms;
  options.backoff_max = 500ms;
  options.connect_timeout = 3000ms;
  options.pose_poll_interval = 100ms;
  return std::make_shared<daemon::Rig>(
      std::make_unique<drivers::Pr650Spectroradiometer>(meter),
      daemon::Rig::DeviceInfo{"PR-650", sim.pr650_path()}, std::move(*created),
      daemon::Rig::DeviceInfo{"Modbus stage (az profile)",
                              sim.modbus_host() + ":" + std::to_string(sim.modbus_port())},
      rig, options);
}

daemon::SessionManager::Options ManagerOptions(bool pipelining) {
  daemon::SessionManager::Options o;
  o.rig_description = SimRigDescription();
  o.pipelining = pipelining;
  return o;
}

v1::Plan PlanFromJson(const std::string& json) {
  Result<v1::Plan> plan = plan::ParsePlanJson(json);
  EXPECT_TRUE(plan.ok()) << plan.status().ToString();
  return plan.ok() ? *plan : v1::Plan();
}

daemon::SessionId IdOf(const v1::Session& s) {
  Result<daemon::SessionId> id = daemon::ParseSessionId(s.session_id());
  return id.ok() ? *id : 0;
}

Operator::Operator(daemon::SessionManager& manager, ModbusControl& control,
                   daemon::SessionId session, bool answer_prompts)
    : manager_(manager), control_(control), session_(session), answering_(answer_prompts) {
  Result<std::shared_ptr<daemon::EventSubscription>> sub = manager_.Subscribe(session_);
  if (!sub.ok()) {
    errors_.push_back(sub.status().ToString());
    return;
  }
  sub_ = *sub;
  thread_ = std::thread([this] { Run(); });
}

Operator::~Operator() {
  Stop();
}

void Operator::Stop() {
  stop_ = true;
  if (thread_.joinable()) thread_.join();
}

std::vector<v1::SessionEvent> Operator::events() const {
  std::lock_guard lock(mu_);
  return events_;
}
std::vector<v1::Prompt> Operator::prompts_answered() const {
  std::lock_guard lock(mu_);
  return answered_;
}
std::vector<std::string> Operator::errors() const {
  std::lock_guard lock(mu_);
  return errors_;
}

void Operator::Run() {
  std::optional<v1::Prompt> open;
  while (!stop_ && !sub_->ended()) {
    std::optional<v1::SessionEvent> event = sub_->Next(20ms);
    if (event.has_value()) {
      std::lock_guard lock(mu_);
      events_.push_back(*event);
      if (event->has_prompt()) open = event->prompt();
      if (event->has_snapshot() && event->snapshot().has_pending_prompt()) {
        open = event->snapshot().pending_prompt();
      }
      if (event->has_state_changed() &&
          event->state_changed().to() != v1::SESSION_STATE_AWAITING_OPERATOR) {
        open.reset();
      }
    }
    if (!open.has_value() || !answering_) continue;
    // Do what the prompt asks on the simulated rig, then confirm it.
    Status acted = Status::Ok();
    switch (open->kind()) {
      case v1::PROMPT_KIND_MOUNT_WHITE:
        acted = control_.SetMounted(sim::MountedTarget::kWhite);
        break;
      case v1::PROMPT_KIND_MOUNT_SAMPLE:
        acted = control_.SetMounted(sim::MountedTarget::kSample);
        break;
      case v1::PROMPT_KIND_CLOSE_SHUTTER:
        acted = control_.SetMounted(sim::MountedTarget::kDark);
        break;
      default:
        break;  // relocations: the simulated lamp and detector follow the stage
    }
    Result<v1::Session> answered =
        acted.ok() ? manager_.AnswerPrompt(session_, open->step_index(), "done", kTestOperator)
                   : Result<v1::Session>(acted);
    std::lock_guard lock(mu_);
    if (answered.ok()) {
      answered_.push_back(*open);
    } else if (answered.status().code() != StatusCode::kFailedPrecondition) {
      // (FailedPrecondition: paused meanwhile; the prompt comes again on resume.)
      errors_.push_back(answered.status().ToString());
    }
    open.reset();
  }
}

v1::Session WaitForSession(daemon::SessionManager& manager, daemon::SessionId session,
                           const std::function<bool(const v1::Session&)>& done,
                           std::chrono::milliseconds timeout) {
  const auto until = std::chrono::steady_clock::now() + timeout;
  v1::Session last;
  for (;;) {
    Result<v1::Session> s = manager.GetSession(session);
    if (s.ok()) {
      last = *s;
      if (done(last)) return last;
    }
    if (std::chrono::steady_clock::now() >= until) return last;
    std::this_thread::sleep_for(10ms);
  }
}

}  // namespace brdf::testing
