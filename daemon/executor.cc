#include "daemon/executor.h"

#include <spdlog/spdlog.h>

#include <algorithm>
#include <thread>
#include <utility>

#include "core/geometry.h"
#include "core/plan/timing.h"
#include "daemon/engine_steps.h"

namespace brdf::daemon {
namespace {

// Errors a later attempt may cure: the device was slow, busy, alarmed, disconnected or garbled.
// Not: a pose beyond travel, a bad configuration, a bug.
bool Retryable(const Status& s) {
  switch (s.code()) {
    case StatusCode::kTimeout:
    case StatusCode::kDeviceError:
    case StatusCode::kProtocolError:
    case StatusCode::kDisconnected:
    case StatusCode::kFailedPrecondition:
      return true;
    default:
      return false;
  }
}

std::string StepName(const storage::StepRecord& step) {
  std::string name = "step " + std::to_string(step.step_index);
  if (!step.label.empty()) name += " (" + step.label + ")";
  return name;
}

// A move started on a second thread while the meter transfers (pipelining).
struct PipelinedMove {
  int step_index = -1;
  std::thread thread;
  std::optional<Result<Pose>> result;

  bool started() const { return step_index >= 0; }
  void Join() {
    if (thread.joinable()) thread.join();
  }
  void Reset() {
    Join();
    step_index = -1;
    result.reset();
  }
  ~PipelinedMove() { Join(); }
};

}  // namespace

struct Executor::Context {
  storage::SessionRecord session;
  std::vector<storage::StepRecord> steps;
  plan::PlanSettings settings;
  bool sample_fixed = false;
  std::vector<double> estimate_s;  // per step, by the timing model
  double remaining_s = 0;          // estimate of the pending steps
  std::vector<int> move_before;    // index of the last move step before each step, or -1
  int pending = 0;
  int done_steps = 0;
  int total_samples = 0;
  int done_samples = 0;
  std::optional<std::int64_t> last_reference;
  std::optional<std::int64_t> last_dark;
  // Where the stage is known to be: the commanded pose of the last move that finished in this
  // run (nullopt at the start of a run and after a failed or cancelled move), and the feedback.
  std::optional<Pose> stage_target;
  Pose stage_feedback;
  bool meter_configured = false;
  bool meter_dark = false;  // the dark flag the meter was last configured with
  bool meter_recorded = false;
  int last_quality = -1;
  std::uint32_t next_move_first_attempt = 1;

  void MarkDone(int index) {
    storage::StepRecord& s = steps[static_cast<std::size_t>(index)];
    if (s.state != storage::StepState::kPending) return;
    s.state = storage::StepState::kDone;
    --pending;
    ++done_steps;
    if (s.kind == storage::StepKind::kSample) ++done_samples;
    remaining_s = std::max(0.0, remaining_s - estimate_s[static_cast<std::size_t>(index)]);
  }
};

Executor::Executor(std::int64_t session, std::shared_ptr<storage::SessionStore> store, Rig& rig,
                   ExecutorHost& host, Options options)
    : session_(session), store_(std::move(store)), rig_(rig), host_(host), options_(options) {}

Executor::~Executor() = default;

void Executor::Cancel(const std::string& reason) {
  cancel_.Cancel(reason);
  {
    std::lock_guard lock(answer_mu_);
    wake_ = true;
  }
  answer_cv_.notify_all();
}

void Executor::Answered(int step_index) {
  {
    std::lock_guard lock(answer_mu_);
    answered_step_ = step_index;
    wake_ = true;
  }
  answer_cv_.notify_all();
}

CallContext Executor::DeviceContext() const {
  return CallContext::WithTimeout(options_.device_call_timeout, cancel_, *options_.clock);
}

void Executor::Run() {
  Context c;
  const std::string where = "session " + std::to_string(session_);
  Result<storage::SessionRecord> session = store_->GetSession(session_);
  if (!session.ok()) {
    Stop(c, -1, session.status(), "reading " + where + " from the database", false);
    return;
  }
  c.session = std::move(*session);
  Result<std::vector<storage::StepRecord>> steps = store_->GetSteps(session_);
  if (!steps.ok()) {
    Stop(c, -1, steps.status(), "reading the steps of " + where, false);
    return;
  }
  c.steps = std::move(*steps);

  Result<std::shared_ptr<const SessionPlan>> plan = host_.Plan(session_);
  if (!plan.ok()) {
    Stop(c, -1, plan.status(), "reading the plan of " + where, false);
    return;
  }
  c.settings = (*plan)->settings;
  c.sample_fixed = c.session.plan_kind == "sample_fixed";

  const std::vector<plan::StepTime> times =
      plan::EstimateSteps(ToPlanSteps(c.steps), rig_.description(), c.settings.measurement);
  c.estimate_s.resize(c.steps.size(), 0);
  c.move_before.resize(c.steps.size(), -1);
  int last_move = -1;
  for (std::size_t i = 0; i < c.steps.size(); ++i) {
    const storage::StepRecord& s = c.steps[i];
    if (i < times.size()) c.estimate_s[i] = times[i].estimate_s;
    c.move_before[i] = last_move;
    if (s.kind == storage::StepKind::kMove) last_move = static_cast<int>(i);
    if (s.kind == storage::StepKind::kSample) ++c.total_samples;
    if (s.state == storage::StepState::kPending) {
      ++c.pending;
      c.remaining_s += c.estimate_s[i];
    } else {
      ++c.done_steps;
      if (s.kind == storage::StepKind::kSample) ++c.done_samples;
    }
  }

  // The latest reference and dark of the session so far: later samples are divided by them.
  Status scan = store_->ForEachReading(session_, [&c](const storage::ReadingRecord& r) {
    if (r.kind == storage::ReadingKind::kReference) c.last_reference = r.id;
    if (r.kind == storage::ReadingKind::kDark) c.last_dark = r.id;
    return Status::Ok();
  });
  if (!scan.ok()) {
    Stop(c, -1, scan, "reading the readings of " + where, false);
    return;
  }

  spdlog::info("{}: running from step {} ({} of {} steps left)", where,
               c.steps.size() - static_cast<std::size_t>(c.pending), c.pending, c.steps.size());
  int i = 0;
  const int n = static_cast<int>(c.steps.size());
  while (i < n) {
    if (cancel_.cancelled()) break;
    const storage::StepRecord& step = c.steps[static_cast<std::size_t>(i)];
    if (step.state != storage::StepState::kPending) {
      ++i;
      continue;
    }
    Outcome outcome = Outcome::kContinue;
    int advanced = 1;
    switch (step.kind) {
      case storage::StepKind::kMove: {
        const std::uint32_t first = c.next_move_first_attempt;
        c.next_move_first_attempt = 1;
        outcome = RunMove(c, i, first);
        break;
      }
      case storage::StepKind::kPrompt:
        outcome = RunPrompt(c, i);
        break;
      case storage::StepKind::kReference:
      case storage::StepKind::kDark:
      case storage::StepKind::kSample:
        outcome = RunReading(c, i, advanced);
        break;
    }
    if (outcome == Outcome::kStop) break;
    i += advanced;
  }

  if (cancel_.cancelled()) {
    // Pause immediate, abort or shutdown: the canceller has set the state. Make sure nothing
    // keeps turning.
    (void)rig_.StopStage();
    spdlog::info("{}: run cancelled ({})", where, cancel_.reason());
    return;
  }
  if (c.pending == 0) {
    Result<SessionState> done =
        host_.ApplyEvent(session_, SessionEvent::kFinish, "every step done");
    if (done.ok()) spdlog::info("{}: completed", where);
  }
}

Result<Pose> Executor::MoveStage(const Pose& pose, const CallContext& ctx) {
  Pose reached = pose;
  const Status st = rig_.UseStage(ctx, [&](drivers::RotationStage& stage) {
    drivers::StageTarget target;
    target.alpha = pose.alpha;
    target.beta = pose.beta;
    if (stage.HasAxis(drivers::Axis::kGamma)) target.gamma = pose.gamma;
    if (stage.HasAxis(drivers::Axis::kDelta)) target.delta = pose.delta;
    BRDF_RETURN_IF_ERROR(stage.MoveTo(target, ctx));
    Result<Pose> feedback = stage.ReadPose(ctx);
    if (feedback.ok()) {
      reached.alpha = feedback->alpha;
      reached.beta = feedback->beta;
      if (target.gamma.has_value()) reached.gamma = feedback->gamma;
      if (target.delta.has_value()) reached.delta = feedback->delta;
    }
    return Status::Ok();
  });
  if (!st.ok()) return st;
  return reached;
}

void Executor::ResetAlarms(const CallContext& ctx) {
  (void)rig_.UseStage(ctx, [&](drivers::RotationStage& stage) {
    for (drivers::Axis axis : drivers::kAllAxes) {
      if (!stage.HasAxis(axis)) continue;
      Result<drivers::AxisState> state = stage.ReadAxis(axis, ctx);
      if (state.ok() && state->alarm) {
        const Status reset = stage.ResetAlarm(axis, ctx);
        spdlog::info("session {}: reset the {} alarm (code {}) before retrying: {}", session_,
                     drivers::AxisName(axis), state->alarm_code,
                     reset.ok() ? "ok" : reset.ToString());
      }
    }
    return Status::Ok();
  });
}

Status Executor::WithRetry(Context& c, int index, std::uint32_t first_attempt,
                           const std::function<Status(std::uint32_t attempt)>& attempt_fn) {
  const plan::RetrySettings& retry = c.settings.retry;
  const std::uint32_t max_attempts = std::max<std::uint32_t>(1, retry.max_attempts);
  Status last = Internal("no attempt was made");
  for (std::uint32_t attempt = first_attempt; attempt <= max_attempts; ++attempt) {
    if (attempt > 1) {
      const auto wait = std::chrono::milliseconds(plan::BackoffBeforeAttemptMs(retry, attempt));
      if (wait.count() > 0 && !options_.clock->SleepFor(wait, &cancel_)) {
        return Cancelled("cancelled while waiting to retry (" + cancel_.reason() + ")");
      }
    }
    if (cancel_.cancelled()) return Cancelled(cancel_.reason());
    Status st = attempt_fn(attempt);
    if (st.ok()) return st;
    if (cancel_.cancelled() || st.code() == StatusCode::kCancelled) {
      return Cancelled(st.message());
    }
    const bool will_retry = Retryable(st) && attempt < max_attempts;
    v1::Fault fault;
    fault.set_step_index(index);
    fault.set_code(StatusCodeName(st.code()));
    fault.set_reason(st.message());
    fault.set_device_code(st.device_code());
    fault.set_attempt(attempt);
    fault.set_will_retry(will_retry);
    fault.set_last_quality_code(c.last_quality);
    *fault.mutable_time() = NowTimestamp();
    host_.Fault(session_, fault);
    spdlog::warn("session {}: step {} attempt {}/{} failed: {}{}", session_, index, attempt,
                 max_attempts, st.ToString(), will_retry ? " (will retry)" : "");
    last = st;
    if (!will_retry) return st;
  }
  return last;
}

Executor::Outcome Executor::Stop(Context& c, int index, const Status& status,
                                 const std::string& what, bool reported) {
  if (cancel_.cancelled() || status.code() == StatusCode::kCancelled) return Outcome::kStop;
  const std::string reason = what + ": " + status.ToString();
  if (!reported) {
    v1::Fault fault;
    fault.set_step_index(index);
    fault.set_code(StatusCodeName(status.code()));
    fault.set_reason(reason);
    fault.set_device_code(status.device_code());
    fault.set_attempt(1);
    fault.set_will_retry(false);
    fault.set_last_quality_code(c.last_quality);
    *fault.mutable_time() = NowTimestamp();
    host_.Fault(session_, fault);
  }
  spdlog::error("session {}: {}", session_, reason);
  const SessionEvent event =
      status.code() == StatusCode::kInternal ? SessionEvent::kError : SessionEvent::kFault;
  (void)host_.ApplyEvent(session_, event, reason);
  return Outcome::kStop;
}

v1::StepCompletion Executor::Completion(const Context& c, int index) const {
  v1::StepCompletion done;
  done.set_step_index(index);
  done.set_kind(ToProtoKind(c.steps[static_cast<std::size_t>(index)].kind));
  v1::Progress* p = done.mutable_progress();
  p->set_done_steps(static_cast<std::uint32_t>(c.done_steps));
  p->set_total_steps(static_cast<std::uint32_t>(c.steps.size()));
  p->set_done_samples(static_cast<std::uint32_t>(c.done_samples));
  p->set_total_samples(static_cast<std::uint32_t>(c.total_samples));
  done.set_eta_s(c.remaining_s);
  done.set_quality_code(-1);
  return done;
}

Status Executor::CompleteSimpleStep(Context& c, int index) {
  BRDF_RETURN_IF_ERROR(store_->CompleteStep(session_, index));
  c.MarkDone(index);
  host_.StepCompleted(session_, Completion(c, index), nullptr);
  return Status::Ok();
}

Executor::Outcome Executor::AfterStep(Context& c) {
  // The last step: kFinish follows (a pending deferred pause does not hold a finished session).
  if (c.pending == 0) return Outcome::kContinue;
  Result<SessionState> next = host_.ApplyEvent(session_, SessionEvent::kStepDone, "");
  if (!next.ok()) return Outcome::kStop;
  return *next == SessionState::kRunning ? Outcome::kContinue : Outcome::kStop;
}

Executor::Outcome Executor::RunMove(Context& c, int index, std::uint32_t first_attempt) {
  const storage::StepRecord& step = c.steps[static_cast<std::size_t>(index)];
  const Status st = WithRetry(c, index, first_attempt, [&](std::uint32_t attempt) {
    const CallContext ctx = DeviceContext();
    if (attempt > 1) ResetAlarms(ctx);
    c.stage_target.reset();
    Result<Pose> reached = MoveStage(step.pose, ctx);
    if (!reached.ok()) return reached.status();
    c.stage_target = step.pose;
    c.stage_feedback = *reached;
    return Status::Ok();
  });
  if (!st.ok()) return Stop(c, index, st, "moving the stage at " + StepName(step), true);
  if (Status done = CompleteSimpleStep(c, index); !done.ok()) {
    return Stop(c, index, done, "recording " + StepName(step) + " as done", false);
  }
  return AfterStep(c);
}

Executor::Outcome Executor::RunPrompt(Context& c, int index) {
  const storage::StepRecord& step = c.steps[static_cast<std::size_t>(index)];
  v1::Prompt prompt = ToPrompt(step);
  *prompt.mutable_raised_at() = NowTimestamp();
  {
    std::lock_guard lock(answer_mu_);
    answered_step_.reset();
  }
  Result<SessionState> state = host_.RaisePrompt(session_, prompt);
  if (!state.ok() || *state != SessionState::kAwaitingOperator) return Outcome::kStop;
  {
    std::unique_lock lock(answer_mu_);
    answer_cv_.wait(lock, [&] {
      return cancel_.cancelled() || (answered_step_.has_value() && *answered_step_ == index);
    });
  }
  if (cancel_.cancelled()) return Outcome::kStop;
  // The host stored the done mark and applied kAnswer (the session runs on).
  c.MarkDone(index);
  host_.StepCompleted(session_, Completion(c, index), nullptr);
  return Outcome::kContinue;
}

Executor::Outcome Executor::RunReading(Context& c, int index, int& advanced) {
  advanced = 1;
  const storage::StepRecord& step = c.steps[static_cast<std::size_t>(index)];
  const plan::RigDescription& rig = rig_.description();
  const int move_index = c.move_before[static_cast<std::size_t>(index)];
  // Where the stage must be: where the last move before this step put it. Sample-fixed plans
  // have no moves: the holder stays where it is.
  std::optional<Pose> required;
  if (move_index >= 0) required = c.steps[static_cast<std::size_t>(move_index)].pose;

  const std::size_t next = static_cast<std::size_t>(index) + 1;
  const bool next_is_move = next < c.steps.size() &&
                            c.steps[next].kind == storage::StepKind::kMove &&
                            c.steps[next].state == storage::StepState::kPending;
  const bool pipeline =
      options_.pipelining && next_is_move && host_.CurrentState(session_) == SessionState::kRunning;

  drivers::MeasurementSettings settings;
  settings.integration_ms = static_cast<int>(c.settings.measurement.integration_ms);
  settings.averages = static_cast<int>(std::max<std::uint32_t>(1, c.settings.measurement.averages));
  // A dark is weak by nature: the driver accepts its low-light codes instead of failing them.
  settings.dark = step.kind == storage::StepKind::kDark;

  drivers::MeasurementOutcome outcome;
  drivers::SpectrumReport report;
  Pose pose = step.pose;
  int measurements = 0;
  PipelinedMove move;

  // After a pipelined move finished: the stage is there (or nowhere known).
  auto settle_move = [&] {
    if (!move.started()) return;
    move.Join();
    if (move.result.has_value() && move.result->ok()) {
      c.stage_target = c.steps[next].pose;
      c.stage_feedback = move.result->value();
    } else {
      c.stage_target.reset();
    }
  };

  const Status st = WithRetry(c, index, 1, [&](std::uint32_t attempt) -> Status {
    const CallContext ctx = DeviceContext();
    if (move.started()) {  // a failed attempt's pipelined move: forget it, move back below
      settle_move();
      move.Reset();
    }
    if (required.has_value() && (!c.stage_target.has_value() || !(*c.stage_target == *required))) {
      if (attempt > 1) ResetAlarms(ctx);
      c.stage_target.reset();
      Result<Pose> reached = MoveStage(*required, ctx);
      if (!reached.ok()) {
        return reached.status().WithContext("moving to the pose of " + StepName(step) +
                                            " before measuring");
      }
      c.stage_target = *required;
      c.stage_feedback = *reached;
    }
    if (required.has_value()) {
      pose.alpha = c.stage_feedback.alpha;
      pose.beta = c.stage_feedback.beta;
      if (rig.has_gamma_axis) pose.gamma = c.stage_feedback.gamma;
      if (rig.has_detector_arm) pose.delta = c.stage_feedback.delta;
    }
    return rig_.UseMeter(ctx, [&](drivers::Spectroradiometer& meter) -> Status {
      if (!c.meter_configured || attempt > 1 || c.meter_dark != settings.dark) {
        BRDF_RETURN_IF_ERROR(meter.Configure(settings, ctx).WithContext("configuring the meter"));
        c.meter_configured = true;
        c.meter_dark = settings.dark;
      }
      // Called once the meter holds an accepted measurement, while its spectrum still streams in.
      auto measured = [&](const drivers::MeasurementOutcome& done) {
        c.last_quality = done.quality_code;
        measurements += done.attempts;  // counted even if the transfer then fails
        if (!pipeline) return;
        // The stage may leave now: the measurement is taken, only its transfer is left.
        move.step_index = static_cast<int>(next);
        c.stage_target.reset();
        const Pose target = c.steps[next].pose;
        spdlog::debug("session {}: step {} moves while step {} transfers", session_, next, index);
        move.thread = std::thread(
            [this, &move, target, ctx] { move.result.emplace(MoveStage(target, ctx)); });
      };
      Result<drivers::MeasuredSpectrum> taken = meter.MeasureSpectrum(ctx, measured);
      if (!taken.ok()) {
        if (taken.status().code() == StatusCode::kDeviceError) {
          c.last_quality = taken.status().device_code();
        }
        return taken.status().WithContext("measuring the spectrum of " + StepName(step));
      }
      outcome = taken->outcome;
      report = std::move(taken->report);
      return Status::Ok();
    });
  });
  if (!st.ok()) {
    settle_move();
    return Stop(c, index, st, "taking the reading of " + StepName(step), true);
  }
  if (cancel_.cancelled()) {  // nothing is written after a cancel: resume redoes the step
    settle_move();
    return Outcome::kStop;
  }

  storage::ReadingRecord reading;
  reading.kind = storage::ReadingKindFor(step.kind).value_or(storage::ReadingKind::kSample);
  reading.pose = pose;
  if (c.sample_fixed && step.target.has_value()) {
    reading.directions = *step.target;  // lamp and detector were placed by hand at the target
  } else {
    reading.directions = PoseToDirections(pose, rig.convention);
  }
  reading.grid = report.grid;
  reading.spectrum = std::move(report.radiance);
  reading.quality_code = outcome.quality_code;
  reading.flagged = outcome.flagged;
  reading.integration_ms = outcome.integration_ms;
  reading.attempts = std::max(1, measurements);
  reading.note = outcome.note;
  if (reading.kind == storage::ReadingKind::kSample) {
    reading.reference_reading_id = c.last_reference;
    reading.dark_reading_id = c.last_dark;
  }
  if (std::optional<drivers::MeterIdentity> id = rig_.meter_identity(); id.has_value()) {
    reading.meter_serial = id->serial_number;
    if (!c.meter_recorded) {
      c.meter_recorded = true;
      if (c.session.meter_serial != id->serial_number) {
        (void)store_->SetSessionMeterSerial(session_, id->serial_number);
      }
      storage::DeviceRecord device;
      device.session_id = session_;
      device.kind = "spectroradiometer";
      device.model = id->model;
      device.serial = id->serial_number;
      (void)store_->RecordDevice(device);
    }
  }

  // The reading and the step's done mark in one transaction (the move, if pipelined, runs on).
  Result<std::int64_t> id = store_->CompleteStepWithReading(session_, index, reading);
  if (!id.ok()) {
    settle_move();
    return Stop(c, index, id.status(), "storing the reading of " + StepName(step), false);
  }
  reading.id = *id;
  reading.session_id = session_;
  reading.step_index = index;
  if (reading.kind == storage::ReadingKind::kReference) c.last_reference = *id;
  if (reading.kind == storage::ReadingKind::kDark) c.last_dark = *id;
  c.MarkDone(index);
  v1::StepCompletion done = Completion(c, index);
  done.set_reading_id(*id);
  done.set_quality_code(reading.quality_code);
  done.set_flagged(reading.flagged);
  host_.StepCompleted(session_, done, &reading);

  if (move.started()) {
    settle_move();
    if (cancel_.cancelled()) return Outcome::kStop;
    const int move_step = static_cast<int>(next);
    if (move.result.has_value() && move.result->ok()) {
      // Only now, after reading `index` is committed, the move's done mark.
      if (Status marked = CompleteSimpleStep(c, move_step); !marked.ok()) {
        return Stop(c, move_step, marked, "recording " + StepName(c.steps[next]) + " as done",
                    false);
      }
      advanced = 2;
    } else {
      const Status failed = move.result.has_value() ? move.result->status()
                                                    : Internal("pipelined move left no result");
      if (failed.code() == StatusCode::kCancelled) return Outcome::kStop;
      const std::uint32_t max_attempts = std::max<std::uint32_t>(1, c.settings.retry.max_attempts);
      const bool will_retry = Retryable(failed) && max_attempts > 1;
      v1::Fault fault;
      fault.set_step_index(move_step);
      fault.set_code(StatusCodeName(failed.code()));
      fault.set_reason(failed.message());
      fault.set_device_code(failed.device_code());
      fault.set_attempt(1);
      fault.set_will_retry(will_retry);
      fault.set_last_quality_code(c.last_quality);
      *fault.mutable_time() = NowTimestamp();
      host_.Fault(session_, fault);
      if (!will_retry) {
        return Stop(c, move_step, failed, "moving the stage at " + StepName(c.steps[next]), true);
      }
      c.next_move_first_attempt = 2;  // the loop runs the move next, as its second attempt
    }
  }
  return AfterStep(c);
}

}  // namespace brdf::daemon
