#include "drivers/stage/modbus_stage.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <set>
#include <utility>

namespace brdf::drivers::stage {

namespace {

using std::chrono::duration;
using std::chrono::duration_cast;

std::string Deg(double v) {
  char buf[32];
  std::snprintf(buf, sizeof buf, "%.3f°", v);
  return buf;
}

std::string AlarmHex(int code) {
  char buf[16];
  std::snprintf(buf, sizeof buf, "0x%02X", static_cast<unsigned>(code));
  return buf;
}

Clock::Duration Seconds(double s) {
  return duration_cast<Clock::Duration>(duration<double>(s));
}

std::optional<double> TargetFor(const StageTarget& t, Axis axis) {
  switch (axis) {
    case Axis::kAlpha:
      return t.alpha;
    case Axis::kBeta:
      return t.beta;
    case Axis::kGamma:
      return t.gamma;
    case Axis::kDelta:
      return t.delta;
  }
  return std::nullopt;
}

bool GaveUp(const Status& st, const CallContext& ctx) {
  return (st.code() == StatusCode::kCancelled && ctx.cancelled()) ||
         (st.code() == StatusCode::kTimeout && ctx.expired());
}

// " while moving to 12.5°" / " while homing", for messages about an axis in motion.
std::string Where(const std::optional<double>& target_deg) {
  return target_deg ? " while moving to " + Deg(*target_deg) : std::string(" while homing");
}

}  // namespace

class ModbusStage::MotionGuard {
 public:
  explicit MotionGuard(std::atomic<bool>& flag) : flag_(flag) {
    bool expected = false;
    owns_ = flag_.compare_exchange_strong(expected, true);
  }
  ~MotionGuard() {
    if (owns_) flag_.store(false);
  }
  MotionGuard(const MotionGuard&) = delete;
  MotionGuard& operator=(const MotionGuard&) = delete;
  bool owns() const { return owns_; }

 private:
  std::atomic<bool>& flag_;
  bool owns_ = false;
};

Status ValidateStageConfig(const ModbusStageConfig& c) {
  BRDF_RETURN_IF_ERROR(ValidateProfile(c.profile));
  auto fail = [](const std::string& field, const std::string& problem) {
    return ConfigurationError("stage configuration field '" + field + "': " + problem +
                              "; fix the stage configuration");
  };
  if (c.buses.empty()) return fail("buses", "no bus is configured");
  for (std::size_t i = 0; i < c.buses.size(); ++i) {
    BRDF_RETURN_IF_ERROR(ValidateBus(static_cast<int>(i), c.buses[i]));
  }
  std::set<std::pair<int, int>> units;  // (bus, unit id)
  for (Axis axis : kAllAxes) {
    const AxisConfig& a = c.axes[static_cast<int>(axis)];
    if (!a.present) {
      if (axis == Axis::kAlpha || axis == Axis::kBeta) {
        return fail(std::string("axes.") + AxisName(axis) + ".present",
                    "alpha and beta are required on every rig");
      }
      continue;
    }
    BRDF_RETURN_IF_ERROR(ValidateAxis(axis, a, c.profile));
    if (a.bus >= static_cast<int>(c.buses.size())) {
      return fail(std::string("axes.") + AxisName(axis) + ".bus",
                  "bus " + std::to_string(a.bus) + " is not configured (" +
                      std::to_string(c.buses.size()) + " bus(es))");
    }
    if (!units.insert({a.bus, a.unit_id}).second) {
      return fail(std::string("axes.") + AxisName(axis) + ".unit_id",
                  "unit id " + std::to_string(a.unit_id) + " is used twice on bus " +
                      std::to_string(a.bus));
    }
    if (!(c.position_tolerance_deg * a.counts_per_degree >= 1.0)) {
      return fail("position_tolerance_deg",
                  Deg(c.position_tolerance_deg) + " is less than one count of axis " +
                      AxisName(axis) + " (" + Deg(1.0 / a.counts_per_degree) + ")");
    }
  }
  if (c.poll_interval <= Clock::Duration::zero()) return fail("poll_interval", "must be positive");
  if (c.pulse_hold < Clock::Duration::zero()) return fail("pulse_hold", "must not be negative");
  if (c.move_margin < Clock::Duration::zero()) return fail("move_margin", "must not be negative");
  if (c.start_grace < Clock::Duration::zero()) return fail("start_grace", "must not be negative");
  if (c.stop_timeout <= Clock::Duration::zero()) return fail("stop_timeout", "must be positive");
  return Status::Ok();
}

Result<std::unique_ptr<ModbusStage>> ModbusStage::Create(ModbusStageConfig config) {
  BRDF_RETURN_IF_ERROR(ValidateStageConfig(config));
  return std::unique_ptr<ModbusStage>(new ModbusStage(std::move(config)));
}

ModbusStage::ModbusStage(ModbusStageConfig config) : config_(std::move(config)) {
  for (const auto& bus : config_.buses) buses_.push_back(std::make_unique<ModbusBus>(bus));
  for (Axis axis : kAllAxes) {
    const AxisConfig& a = config_.axes[static_cast<int>(axis)];
    if (!a.present) continue;
    axes_[static_cast<int>(axis)] = std::make_unique<AxisIo>(
        axis, a, config_.profile, *buses_[static_cast<std::size_t>(a.bus)]);
  }
}

ModbusStage::~ModbusStage() {
  Disconnect();
}

bool ModbusStage::HasAxis(Axis axis) const {
  return IoFor(axis) != nullptr;
}

Status ModbusStage::RequireConnected(const char* what) const {
  if (connected_.load()) return Status::Ok();
  return FailedPrecondition(std::string("stage: cannot ") + what +
                            ": the stage is not connected; call Connect first");
}

Status ModbusStage::Connect(const CallContext& ctx) {
  if (connected_.load()) return Status::Ok();
  for (auto& bus : buses_) {
    Status st = bus->Open(ctx);
    if (!st.ok()) {
      Disconnect();
      return st.WithContext("stage: connecting");
    }
  }
  for (const auto& io : axes_) {
    if (!io) continue;
    auto status = io->ReadStatus(ctx);
    if (!status.ok()) {
      Disconnect();
      return status.status().WithContext("stage: connecting (first status read)");
    }
  }
  connected_.store(true);
  return Status::Ok();
}

void ModbusStage::Disconnect() {
  connected_.store(false);
  for (auto& bus : buses_) bus->Close();
}

Status ModbusStage::CheckNoAlarm(const AxisIo& io, const CallContext& ctx) const {
  BRDF_ASSIGN_OR_RETURN(auto status, io.ReadStatus(ctx));
  if (status.flags.alarm) {
    return FailedPrecondition(io.name() + " has alarm " + AlarmHex(status.alarm_code) +
                              " set; remove its cause, then call ResetAlarm(" +
                              AxisName(io.axis()) + ") before moving");
  }
  return Status::Ok();
}

Status ModbusStage::PulseCommand(const std::vector<const AxisIo*>& axes,
                                 const CommandAction& command, const char* command_name,
                                 const CallContext& ctx, BusPriority priority) {
  Status first;
  std::vector<const AxisIo*> set;
  for (const AxisIo* io : axes) {
    Status st = io->SetCommand(command, command_name, true, ctx, priority);
    if (st.ok()) {
      set.push_back(io);
    } else if (first.ok()) {
      first = st;
    }
  }
  if (command.kind == CommandAction::Kind::kPulseBits && !set.empty()) {
    // Level inputs: the drive acts on the edge, but the bit must be seen set before it clears.
    // Clearing must happen even when the caller is cancelled meanwhile.
    ctx.clock().SleepFor(config_.pulse_hold);
    const CallContext clear_ctx(ctx.deadline(), CancelToken(), ctx.clock());
    for (const AxisIo* io : set) {
      Status st = io->SetCommand(command, command_name, false, clear_ctx, priority);
      if (!st.ok() && first.ok()) first = st;
    }
  }
  return first;
}

std::string ModbusStage::StopAfterFailure(const std::vector<const AxisIo*>& axes,
                                          const Clock& clock) {
  if (axes.empty()) return "";
  const CallContext stop_ctx = CallContext::WithTimeout(config_.stop_timeout, CancelToken(), clock);
  Status st = PulseCommand(axes, config_.profile.stop, "STOP", stop_ctx, BusPriority::kUrgent);
  if (st.ok()) return "; the axes were stopped";
  return "; stopping the axes failed too (" + st.ToString() + "): stop them at the drives";
}

Status ModbusStage::MoveTo(const StageTarget& target, const CallContext& ctx) {
  BRDF_RETURN_IF_ERROR(RequireConnected("move"));
  // 1. Every target is checked before anything moves.
  struct Planned {
    const AxisIo* io;
    double target;
  };
  std::vector<Planned> planned;
  for (Axis axis : kAllAxes) {
    const std::optional<double> t = TargetFor(target, axis);
    if (!t) continue;
    const AxisIo* io = IoFor(axis);
    if (io == nullptr) {
      return InvalidArgument(std::string("stage: a target for axis ") + AxisName(axis) +
                             " was given, but this rig has no " + AxisName(axis) +
                             " axis; leave it empty or configure the axis");
    }
    const AxisConfig& a = io->config();
    if (!std::isfinite(*t)) {
      return InvalidArgument(std::string("stage: target for axis ") + AxisName(axis) +
                             " is not a finite number");
    }
    if (*t < a.min_deg || *t > a.max_deg) {
      const bool below = *t < a.min_deg;
      return InvalidArgument(std::string("stage: target ") + AxisName(axis) + " = " + Deg(*t) +
                             " is outside the travel limit " + (below ? "min " : "max ") +
                             Deg(below ? a.min_deg : a.max_deg) + " of axis " + AxisName(axis) +
                             " (limits " + Deg(a.min_deg) + " to " + Deg(a.max_deg) +
                             "); choose a pose inside the limits");
    }
    planned.push_back({io, *t});
  }
  if (planned.empty()) return Status::Ok();

  MotionGuard guard(in_motion_);
  if (!guard.owns()) {
    return FailedPrecondition(
        "stage: another move or homing is in progress; wait for it to finish or call Stop");
  }

  // 2. No axis may start while any named axis has an alarm; note where each one is.
  std::vector<Motion> motions;
  for (const Planned& p : planned) {
    BRDF_RETURN_IF_ERROR(CheckNoAlarm(*p.io, ctx).WithContext("stage: move refused"));
    auto from = p.io->ReadPositionDeg(ctx);
    if (!from.ok()) return from.status().WithContext("stage: move");
    Motion m;
    m.io = p.io;
    m.target_deg = p.target;
    m.expected_s = std::abs(p.target - *from) / p.io->config().speed_deg_s;
    motions.push_back(m);
  }

  // 3. Start them all, then wait for them all.
  std::vector<const AxisIo*> started;
  for (Motion& m : motions) {
    Status st = m.io->StartMove(*m.target_deg, ctx);
    const Clock::TimePoint now = ctx.clock().Now();
    m.started = now;
    m.timeout_at = now + Seconds(m.expected_s) + config_.move_margin;
    if (!st.ok()) {
      // The write may have reached the drive before failing: stop this axis too.
      started.push_back(m.io);
      const std::string note = StopAfterFailure(started, ctx.clock());
      if (GaveUp(st, ctx) && ctx.cancelled()) {
        return Cancelled("stage: move cancelled while starting " + m.io->name() + note);
      }
      return Status(st.code(), "stage: starting the move: " + st.message() + note,
                    st.device_code());
    }
    started.push_back(m.io);
  }
  return WaitForMotion(motions, ctx, "move");
}

Status ModbusStage::WaitForMotion(std::vector<Motion>& motions, const CallContext& ctx,
                                  const char* what) {
  std::vector<const AxisIo*> all;
  for (const Motion& m : motions) all.push_back(m.io);
  const Clock& clock = ctx.clock();
  while (true) {
    if (ctx.cancelled()) {
      return Cancelled(std::string("stage: ") + what + " cancelled (" + ctx.cancel().reason() +
                       ")" + StopAfterFailure(all, clock));
    }
    if (ctx.expired()) {
      return Timeout(std::string("stage: the call's deadline passed during the ") + what +
                     StopAfterFailure(all, clock) + "; allow more time for the call");
    }
    bool all_done = true;
    bool gave_up = false;
    for (Motion& m : motions) {
      if (m.done) continue;
      BRDF_RETURN_IF_ERROR(PollMotion(m, all, ctx, what, gave_up));
      if (gave_up) break;
      all_done = all_done && m.done;
    }
    if (gave_up) continue;  // the checks at the top report it
    if (all_done) return Status::Ok();
    clock.SleepFor(config_.poll_interval, &ctx.cancel());
  }
}

Status ModbusStage::PollMotion(Motion& m, const std::vector<const AxisIo*>& all,
                               const CallContext& ctx, const char* what, bool& gave_up) {
  const Clock& clock = ctx.clock();
  auto status = m.io->ReadStatus(ctx);
  if (!status.ok()) {
    if (GaveUp(status.status(), ctx)) {
      gave_up = true;
      return Status::Ok();
    }
    return Status(status.status().code(),
                  std::string("stage: polling during the ") + what + ": " +
                      status.status().message() + StopAfterFailure(all, clock),
                  status.status().device_code());
  }
  const Clock::TimePoint now = clock.Now();
  if (status->flags.alarm) {
    std::vector<const AxisIo*> others;
    for (const AxisIo* io : all) {
      if (io != m.io) others.push_back(io);
    }
    return DeviceError(status->alarm_code, m.io->name() + " raised alarm " +
                                               AlarmHex(status->alarm_code) + Where(m.target_deg) +
                                               StopAfterFailure(others, clock) +
                                               "; remove the cause, then call ResetAlarm(" +
                                               AxisName(m.io->axis()) + ")");
  }
  if (MoveComplete(status->flags)) {
    BRDF_RETURN_IF_ERROR(CheckArrival(m, now, all, ctx, what, gave_up));
    if (gave_up) return Status::Ok();
  }
  if (!m.done && now >= m.timeout_at) {
    const double allowed = duration<double>(m.timeout_at - m.started).count();
    return Timeout(m.io->name() + " did not finish" + Where(m.target_deg) + " within " +
                   std::to_string(allowed) + " s (expected " + std::to_string(m.expected_s) +
                   " s plus margin)" + StopAfterFailure(all, clock) +
                   "; check for a stall, an obstruction or a wrong speed setting");
  }
  return Status::Ok();
}

Status ModbusStage::CheckArrival(Motion& m, Clock::TimePoint now,
                                 const std::vector<const AxisIo*>& all, const CallContext& ctx,
                                 const char* what, bool& gave_up) {
  if (!m.target_deg) {
    // Homing: trust IN-POS once the drive had time to raise MOVE.
    m.done = now - m.started >= config_.start_grace;
    return Status::Ok();
  }
  auto pos = m.io->ReadPositionDeg(ctx);
  if (!pos.ok()) {
    if (GaveUp(pos.status(), ctx)) {
      gave_up = true;
      return Status::Ok();
    }
    return pos.status().WithContext(std::string("stage: ") + what);
  }
  if (std::abs(*pos - *m.target_deg) <= config_.position_tolerance_deg) {
    m.done = true;
  } else if (now - m.started >= config_.start_grace) {
    return DeviceError(0, m.io->name() + " stopped at " + Deg(*pos) + " short of its target " +
                              Deg(*m.target_deg) +
                              " without an alarm (stopped at the "
                              "drive or by another master?)" +
                              StopAfterFailure(all, ctx.clock()) + "; move again");
  }
  return Status::Ok();
}

Result<AxisState> ModbusStage::ReadAxis(Axis axis, const CallContext& ctx) {
  BRDF_RETURN_IF_ERROR(RequireConnected("read an axis"));
  const AxisIo* io = IoFor(axis);
  if (io == nullptr) {
    return InvalidArgument(std::string("stage: this rig has no ") + AxisName(axis) + " axis");
  }
  BRDF_ASSIGN_OR_RETURN(auto status, io->ReadStatus(ctx));
  BRDF_ASSIGN_OR_RETURN(auto pos, io->ReadPositionDeg(ctx));
  AxisState s;
  s.position_deg = pos;
  s.moving = status.flags.moving;
  s.in_position = status.flags.in_position;
  s.ready = status.flags.ready;
  s.alarm = status.flags.alarm;
  s.alarm_code = status.alarm_code;
  return s;
}

Result<Pose> ModbusStage::ReadPose(const CallContext& ctx) {
  BRDF_RETURN_IF_ERROR(RequireConnected("read the pose"));
  Pose pose;
  double* fields[] = {&pose.alpha, &pose.beta, &pose.gamma, &pose.delta};
  for (Axis axis : kAllAxes) {
    const AxisIo* io = IoFor(axis);
    if (io == nullptr) continue;
    BRDF_ASSIGN_OR_RETURN(auto pos, io->ReadPositionDeg(ctx));
    *fields[static_cast<int>(axis)] = pos;
  }
  return pose;
}

Status ModbusStage::ResetAlarm(Axis axis, const CallContext& ctx) {
  BRDF_RETURN_IF_ERROR(RequireConnected("reset an alarm"));
  const AxisIo* io = IoFor(axis);
  if (io == nullptr) {
    return InvalidArgument(std::string("stage: this rig has no ") + AxisName(axis) + " axis");
  }
  BRDF_RETURN_IF_ERROR(
      PulseCommand({io}, config_.profile.alarm_reset, "ALM-RST", ctx, BusPriority::kNormal));
  BRDF_ASSIGN_OR_RETURN(auto status, io->ReadStatus(ctx));
  if (status.flags.alarm) {
    return DeviceError(status.alarm_code,
                       io->name() + ": alarm " + AlarmHex(status.alarm_code) +
                           " is still set after ALM-RST; its cause persists (overtravel, "
                           "obstruction, overheating): remove it at the rig, then reset again");
  }
  return Status::Ok();
}

Status ModbusStage::Home(Axis axis, const CallContext& ctx) {
  BRDF_RETURN_IF_ERROR(RequireConnected("home"));
  const AxisIo* io = IoFor(axis);
  if (io == nullptr) {
    return InvalidArgument(std::string("stage: this rig has no ") + AxisName(axis) + " axis");
  }
  MotionGuard guard(in_motion_);
  if (!guard.owns()) {
    return FailedPrecondition(
        "stage: another move or homing is in progress; wait for it to finish or call Stop");
  }
  BRDF_RETURN_IF_ERROR(CheckNoAlarm(*io, ctx).WithContext("stage: homing refused"));
  const AxisConfig& a = io->config();
  Motion m;
  m.io = io;
  m.expected_s = (a.max_deg - a.min_deg) / a.speed_deg_s;
  m.started = ctx.clock().Now();
  m.timeout_at = m.started + Seconds(m.expected_s) + config_.move_margin;
  BRDF_RETURN_IF_ERROR(
      PulseCommand({io}, config_.profile.home, "ZHOME", ctx, BusPriority::kNormal));
  std::vector<Motion> motions{m};
  return WaitForMotion(motions, ctx, "homing");
}

Status ModbusStage::Stop(const CallContext& ctx) {
  BRDF_RETURN_IF_ERROR(RequireConnected("stop"));
  std::vector<const AxisIo*> all;
  for (const auto& io : axes_) {
    if (io) all.push_back(io.get());
  }
  const CallContext stop_ctx(ctx.deadline(), CancelToken(), ctx.clock());
  return PulseCommand(all, config_.profile.stop, "STOP", stop_ctx, BusPriority::kUrgent)
      .WithContext("stage: stop");
}

}  // namespace brdf::drivers::stage
