// bench_session_time: how long a session takes on brdf-sim against the physical lower bound of its
// plan (core/plan/timing.h), with the executor's pipelining on and off.
//
// For each mode it starts its own brdf-sim (scaled time, 9600-baud pacing ON: the meter's real
// transfer time), builds the daemon's engine on it exactly as brdfd does (daemon::Rig with the
// real PR-650 and Modbus stage drivers, daemon::SessionManager, SQLite storage), submits the same
// plan, plays the operator (mounts the white / the sample on the simulator, answers the prompts)
// and times the session from Start to COMPLETED. The modes run at the same time (two simulated
// rigs), so the comparison takes as long as the slower one.
//
// Why in process and not through brdfd: the host-side waits of the drivers (the stage's
// in-position polling, the meter's command pacing and reply gap) are real time and do not scale
// with the simulator; brdfd's configuration has no key for the stage's poll interval (100 ms) nor
// for pipelining, so a time-scaled brdfd would measure its poll interval, not the executor. Here
// they are set to what a real rig uses relative to its speed (a few ms at this time scale).
//
// Simulated seconds = real seconds × time scale. The bound is the SessionManager's own
// PlanSummary.physical_lower_bound_s (the rig description below, with brdf-sim's 1.0 s of meter
// overhead per measurement, which nothing can overlap), and for pipelining off also the bound of
// a sequential executor (PlanLowerBound(…, pipelined = false)).
//
// Output: one line per mode, "key=value" pairs (bench/daemon/run.sh parses them).
#include <spdlog/spdlog.h>

#include <CLI/CLI.hpp>
#include <atomic>
#include <chrono>
#include <cstdio>
#include <filesystem>
#include <memory>
#include <optional>
#include <string>
#include <thread>
#include <vector>

#include "core/plan/analyze_plan.h"
#include "core/plan/plan_json.h"
#include "core/plan/plan_settings.h"
#include "core/plan/timing.h"
#include "daemon/engine/rig.h"
#include "daemon/engine/session_manager.h"
#include "drivers/pr650/spectroradiometer.h"
#include "drivers/stage/modbus_stage.h"
#include "storage/session_store.h"
#include "tests/support/sim/modbus_control.h"
#include "tests/support/sim/process.h"

namespace brdf::bench {
namespace {

using namespace std::chrono_literals;
using Seconds = std::chrono::duration<double>;

const daemon::Actor kBenchOperator{"operator", "bench"};

struct Settings {
  double time_scale = 20;
  int alpha_step = 9;  // α 0…90: 11 rows
  int beta_step = 15;  // β every 15° where lamp and detector see the sample
  double beta_speed = 10;
  double alpha_speed = 10;
  int integration_ms = 100;
  double meter_overhead_s = 1.0;  // brdf-sim's [optics.detector] overhead_s (its default)
  std::string work;
};

std::string PlanJson(const Settings& s) {
  return R"({"name": "bench: session time", "sampleRotation": {
      "delta": {"start": 10, "stop": 40, "step": 15},
      "alpha": {"start": 0, "stop": 90, "step": )" +
         std::to_string(s.alpha_step) + R"(},
      "beta": {"step": )" +
         std::to_string(s.beta_step) + R"(}},
    "measurement": {"integrationMs": )" +
         std::to_string(s.integration_ms) + R"(, "averages": 1}})";
}

// The simulated rig as the plan code sees it, in simulated seconds.
plan::RigDescription RigOf(const Settings& s) {
  plan::RigDescription rig;
  rig.has_detector_arm = true;
  rig.alpha = {0, 90, s.alpha_speed};
  rig.beta = {-180, 180, s.beta_speed};
  rig.gamma = {-180, 180, 20};
  rig.delta = {0, 180, 20};
  rig.meter_transfer_s = 1730.0 * 10.0 / 9600.0;  // the D5 report at 9600 baud (8N1)
  rig.meter_measure_overhead_s = s.meter_overhead_s;
  rig.reading_overhead_s = 0.05;
  rig.move_settle_s = 0;
  rig.operator_action_s = 0;
  return rig;
}

// The real drivers on `sim`, with host-side waits of a few ms (real time).
Result<std::shared_ptr<daemon::Rig>> MakeRig(const testing::SimProcess& sim,
                                             const plan::RigDescription& rig) {
  drivers::Pr650Options meter;
  meter.port = sim.pr650_path();
  meter.command_pacing = 0ms;
  meter.quiet_gap = 2ms;
  meter.stall_timeout = 300ms;
  meter.reply_timeout = 2000ms;
  meter.measurement_timeout = 5000ms;
  meter.rts_drop = 5ms;
  meter.wake_settle = 10ms;
  meter.wake_attempts = 3;
  meter.log = [](std::string_view) {};
  meter.quality_policy.Set(10, {drivers::pr650::QualityAction::kAcceptAndFlag, true});

  drivers::stage::ModbusStageConfig stage;
  drivers::stage::BusConfig bus;
  bus.endpoint = drivers::stage::TcpEndpoint{sim.modbus_host(), sim.modbus_port()};
  bus.response_timeout = 500ms;
  bus.reconnect_backoff = 10ms;
  bus.busy_backoff = 1ms;
  stage.buses = {bus};
  const plan::AxisTravel* travel[] = {&rig.alpha, &rig.beta, &rig.gamma, &rig.delta};
  for (int i = 0; i < 4; ++i) {
    drivers::stage::AxisConfig& a = stage.axes[static_cast<std::size_t>(i)];
    a.present = i != 2;  // γ is a dial on brdf-sim's default rig
    a.bus = 0;
    a.unit_id = i + 1;
    a.min_deg = travel[i]->min_deg;
    a.max_deg = travel[i]->max_deg;
    a.speed_deg_s = travel[i]->speed_deg_s;
  }
  stage.poll_interval = 2ms;
  stage.pulse_hold = 2ms;
  stage.start_grace = 50ms;
  BRDF_ASSIGN_OR_RETURN(std::unique_ptr<drivers::stage::ModbusStage> created,
                        drivers::stage::ModbusStage::Create(stage));
  daemon::Rig::Options options;
  options.backoff_initial = 50ms;
  options.backoff_max = 500ms;
  options.connect_timeout = 5000ms;
  options.pose_poll_interval = 1000ms;  // the supervisor's live pose: not on the session's path
  return std::make_shared<daemon::Rig>(
      std::make_unique<drivers::Pr650Spectroradiometer>(meter),
      daemon::Rig::DeviceInfo{"PR-650", sim.pr650_path()}, std::move(created),
      daemon::Rig::DeviceInfo{"Modbus stage", sim.modbus_host()}, rig, options);
}

struct Run {
  bool pipelining = true;
  Status status = Status::Ok();
  int steps = 0;
  int readings = 0;
  double wall_s = 0;
  double bound_s = 0;             // the daemon's PlanSummary.physical_lower_bound_s
  double sequential_bound_s = 0;  // the same plan without overlap
};

// Answers prompts (doing what they ask on the simulator) until the session ends; returns the time
// it ended (COMPLETED or another terminal state).
Status Operate(daemon::SessionManager& manager, testing::ModbusControl& control,
               daemon::SessionId id, std::chrono::steady_clock::time_point* ended) {
  BRDF_ASSIGN_OR_RETURN(std::shared_ptr<daemon::EventSubscription> sub, manager.Subscribe(id));
  const auto give_up = std::chrono::steady_clock::now() + 20min;
  while (std::chrono::steady_clock::now() < give_up) {
    std::optional<v1::SessionEvent> event = sub->Next(200ms);
    if (!event.has_value()) {
      if (sub->ended()) break;
      continue;
    }
    std::optional<v1::Prompt> prompt;
    if (event->has_prompt()) prompt = event->prompt();
    if (event->has_snapshot() && event->snapshot().has_pending_prompt()) {
      prompt = event->snapshot().pending_prompt();
    }
    if (event->has_state_changed()) {
      const v1::SessionState to = event->state_changed().to();
      if (to == v1::SESSION_STATE_COMPLETED) {
        *ended = std::chrono::steady_clock::now();
        return Status::Ok();
      }
      if (to == v1::SESSION_STATE_FAILED || to == v1::SESSION_STATE_ABORTED ||
          to == v1::SESSION_STATE_PAUSED) {
        return Internal("session " + std::to_string(id) + " went " + v1::SessionState_Name(to) +
                        ": " + event->state_changed().reason());
      }
    }
    if (!prompt.has_value()) continue;
    Status acted = Status::Ok();
    switch (prompt->kind()) {
      case v1::PROMPT_KIND_MOUNT_WHITE:
        acted = control.SetMounted(sim::MountedTarget::kWhite);
        break;
      case v1::PROMPT_KIND_MOUNT_SAMPLE:
        acted = control.SetMounted(sim::MountedTarget::kSample);
        break;
      case v1::PROMPT_KIND_CLOSE_SHUTTER:
        acted = control.SetMounted(sim::MountedTarget::kDark);
        break;
      default:
        break;
    }
    BRDF_RETURN_IF_ERROR(acted);
    BRDF_RETURN_IF_ERROR(
        manager.AnswerPrompt(id, prompt->step_index(), "bench", kBenchOperator).status());
  }
  return Timeout("session " + std::to_string(id) + " did not complete within 20 minutes");
}

void RunOne(const Settings& s, Run& run) {
  auto fail = [&](const Status& st) { run.status = st; };
  Result<std::unique_ptr<testing::SimProcess>> sim = testing::SimProcess::Start(
      {"--time-scale", std::to_string(s.time_scale), "--seed", "1", "--modbus-port", "0",
       "--wake-window", "0", "--pacing", "--log-level", "warn"});
  if (!sim.ok()) return fail(sim.status());
  Result<std::unique_ptr<testing::ModbusControl>> control = testing::ModbusControl::Connect(
      (*sim)->modbus_host(), (*sim)->modbus_port(), (*sim)->control_unit());
  if (!control.ok()) return fail(control.status());

  const plan::RigDescription description = RigOf(s);
  Result<std::shared_ptr<daemon::Rig>> rig = MakeRig(**sim, description);
  if (!rig.ok()) return fail(rig.status());
  const std::string db =
      s.work + "/session-" + (run.pipelining ? "pipelined" : "sequential") + ".db";
  std::filesystem::remove(db);
  Result<std::unique_ptr<storage::SessionStore>> store = storage::SessionStore::Open(db);
  if (!store.ok()) return fail(store.status());
  daemon::SessionManager::Options options;
  options.rig_description = description;
  options.pipelining = run.pipelining;
  daemon::SessionManager manager(std::move(*store), *rig, options);

  // Both devices up (the meter's wake-up) before the clock starts.
  const auto connect_until = std::chrono::steady_clock::now() + 30s;
  for (;;) {
    const daemon::RigStatus status = (*rig)->GetStatus();
    if (status.meter.connection == daemon::DeviceConnection::kConnected &&
        status.stage.connection == daemon::DeviceConnection::kConnected) {
      break;
    }
    if (std::chrono::steady_clock::now() > connect_until) {
      return fail(Timeout("the simulated rig did not connect within 30 s (meter: " +
                          status.meter.last_error + ", stage: " + status.stage.last_error + ")"));
    }
    std::this_thread::sleep_for(20ms);
  }

  Result<v1::Plan> plan = plan::ParsePlanJson(PlanJson(s));
  if (!plan.ok()) return fail(plan.status());
  Result<v1::Session> submitted = manager.SubmitPlan(*plan, kBenchOperator, false);
  if (!submitted.ok()) return fail(submitted.status());
  Result<daemon::SessionId> id = daemon::ParseSessionId(submitted->session_id());
  if (!id.ok()) return fail(id.status());
  run.steps = static_cast<int>(submitted->summary().step_count());
  run.readings = static_cast<int>(submitted->summary().sample_readings());
  run.bound_s = submitted->summary().physical_lower_bound_s();
  Result<std::vector<plan::Step>> steps = plan::ExpandPlan(*plan, description);
  if (!steps.ok()) return fail(steps.status());
  run.sequential_bound_s =
      plan::PlanLowerBound(*steps, description, plan::ResolveSettings(*plan).measurement, false);

  std::chrono::steady_clock::time_point ended;
  const auto started = std::chrono::steady_clock::now();
  Result<v1::Session> running = manager.Start(*id, kBenchOperator);
  if (!running.ok()) return fail(running.status());
  if (Status st = Operate(manager, **control, *id, &ended); !st.ok()) return fail(st);
  run.wall_s = Seconds(ended - started).count();
  manager.Shutdown(5s);
}

}  // namespace
}  // namespace brdf::bench

int main(int argc, char** argv) {
  using namespace brdf;
  bench::Settings s;
  std::string mode = "both";
  CLI::App app("bench_session_time: session time on brdf-sim against the physical lower bound");
  app.add_option("--time-scale", s.time_scale, "brdf-sim's time scale")->check(CLI::Range(1, 200));
  app.add_option("--mode", mode, "pipelining: on, off or both (at the same time)")
      ->check(CLI::IsMember({"on", "off", "both"}));
  app.add_option("--alpha-step", s.alpha_step, "α step of the plan, degrees (α 0…90)");
  app.add_option("--beta-step", s.beta_step, "β step of the plan, degrees (β −180…180)");
  app.add_option("--integration-ms", s.integration_ms, "fixed integration time");
  app.add_option("--work", s.work, "folder for the databases")->required();
  CLI11_PARSE(app, argc, argv);
  spdlog::set_level(spdlog::level::warn);

  std::vector<bench::Run> runs;
  if (mode != "off") runs.push_back({.pipelining = true});
  if (mode != "on") runs.push_back({.pipelining = false});
  std::vector<std::thread> threads;
  for (bench::Run& r : runs) threads.emplace_back([&s, &r] { bench::RunOne(s, r); });
  for (std::thread& t : threads) t.join();

  int code = 0;
  for (const bench::Run& r : runs) {
    if (!r.status.ok()) {
      std::fprintf(stderr, "bench_session_time: pipelining %s: %s\n", r.pipelining ? "on" : "off",
                   r.status.ToString().c_str());
      code = 1;
      continue;
    }
    const double measured = r.wall_s * s.time_scale;
    std::printf(
        "session pipelining=%s steps=%d samples=%d time_scale=%g wall_s=%.2f measured_sim_s=%.1f "
        "bound_s=%.1f ratio=%.4f sequential_bound_s=%.1f\n",
        r.pipelining ? "on" : "off", r.steps, r.readings, s.time_scale, r.wall_s, measured,
        r.bound_s, measured / r.bound_s, r.sequential_bound_s);
  }
  return code;
}
