#include "daemon/engine/executor.h"

#include <spdlog/spdlog.h>

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <utility>

#include "core/plan/plan_settings.h"
#include "core/plan/sample.h"
#include "core/plan/timing.h"
#include "daemon/engine/reading_step.h"
#include "daemon/engine/retry.h"
#include "daemon/wire/enums.h"
#include "daemon/wire/plan.h"
#include "daemon/wire/values.h"

namespace brdf::daemon {
namespace {

// Unix seconds now, the clock the store stamps readings with (recorded_at).
double WallSeconds() {
  return std::chrono::duration<double>(std::chrono::system_clock::now().time_since_epoch()).count();
}

std::string StepName(const storage::StepRecord& step) {
  std::string name = "step " + std::to_string(step.step_index);
  if (!step.label.empty()) name += " (" + step.label + ")";
  return name;
}

// "α 0.73°, β 72.84°, δ 157.5°" (γ too when not 0): a pose as the operator reads it.
std::string PoseText(const Pose& p) {
  char text[160];
  std::snprintf(text, sizeof text, "α %.4g°, β %.4g°, δ %.4g°", p.alpha, p.beta, p.delta);
  std::string out = text;
  if (p.gamma != 0) {
    std::snprintf(text, sizeof text, ", γ %.4g°", p.gamma);
    out += text;
  }
  return out;
}

}  // namespace

struct Executor::Context {
  storage::SessionRecord session;
  std::vector<storage::StepRecord> steps;
  plan::PlanSettings settings;
  bool sample_fixed = false;       // lamp and detector set by hand (plan::SampleFixedMethod)
  bool adaptive = false;           // an adaptive plan: a sample pose the meter overloads at is
                                   // skipped (SkipsOverloadedPose)
  std::vector<double> estimate_s;  // per step, by the timing model
  double remaining_s = 0;          // estimate of the pending steps
  std::vector<int> move_before;    // index of the last move step before each step, or -1
  int pending = 0;
  int done_steps = 0;
  int total_samples = 0;
  int done_samples = 0;
  std::optional<std::int64_t> last_reference;
  std::optional<std::int64_t> last_dark;
  StageKnowledge stage;
  MeterKnowledge meter;
  std::optional<ReadingBudgeter> budgeter;  // Options::uncertainty set
  std::uint32_t next_move_first_attempt = 1;

  // A pending step finished: done, or skipped (counted as TallySteps counts it on a restart).
  void MarkDone(int index, storage::StepState state = storage::StepState::kDone) {
    storage::StepRecord& s = steps[static_cast<std::size_t>(index)];
    if (s.state != storage::StepState::kPending) return;
    s.state = state;
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
    MutexLock lock(answer_mu_);
    wake_ = true;
  }
  answer_cv_.NotifyAll();
}

void Executor::Answered(int step_index) {
  {
    MutexLock lock(answer_mu_);
    answered_step_ = step_index;
    wake_ = true;
  }
  answer_cv_.NotifyAll();
}

CallContext Executor::DeviceContext() const {
  return CallContext::WithTimeout(options_.device_call_timeout, cancel_, *options_.clock);
}

void Executor::Run() {
  Context c;
  const std::string where = "session " + std::to_string(session_);
  if (!Load(c, where)) return;
  spdlog::info("{}: running from step {} ({} of {} steps left)", where,
               c.steps.size() - static_cast<std::size_t>(c.pending), c.pending, c.steps.size());
  std::string finish_reason;
  do {
    RunSteps(c);
    if (cancel_.cancelled()) {
      // Pause immediate, abort or shutdown: the canceller has set the state. Make sure nothing
      // keeps turning.
      (void)rig_.StopStage();
      spdlog::info("{}: run cancelled ({})", where, cancel_.reason());
      return;
    }
    if (c.pending != 0) return;  // stopped (paused, faulted)
  } while (MoreSteps(c, where, finish_reason));
  if (c.pending != 0 || finish_reason.empty()) return;
  EstimateBudgetsAgain(c, where);
  Result<SessionState> done = host_.ApplyEvent(session_, SessionEvent::kFinish, finish_reason);
  if (done.ok()) spdlog::info("{}: completed ({})", where, finish_reason);
}

bool Executor::MoreSteps(Context& c, const std::string& where, std::string& finish_reason) {
  Result<ExecutorHost::LastStepOutcome> outcome = host_.AfterLastStep(session_);
  if (!outcome.ok()) {
    Stop(c, -1, outcome.status(), "choosing what follows the last step of " + where, false);
    return false;
  }
  if (!outcome->more_steps) {
    finish_reason = outcome->finish_reason;
    return false;
  }
  Result<std::vector<storage::StepRecord>> steps = store_->GetSteps(session_);
  if (!steps.ok()) {
    Stop(c, -1, steps.status(), "reading the steps of " + where, false);
    return false;
  }
  c.steps = std::move(*steps);
  c.estimate_s.clear();
  c.move_before.clear();
  c.pending = c.done_steps = c.total_samples = c.done_samples = 0;
  c.remaining_s = 0;
  TallySteps(c);
  // A deferred pause asked while the round was chosen takes effect here, as after any step.
  Result<SessionState> next = host_.ApplyEvent(session_, SessionEvent::kStepDone, "");
  return next.ok() && *next == SessionState::kRunning;
}

void Executor::EstimateBudgetsAgain(Context& c, const std::string& where) {
  if (!c.budgeter.has_value()) return;
  std::vector<storage::ReadingRecord> samples;
  Status scan = store_->ForEachReading(session_, [&samples](const storage::ReadingRecord& r) {
    if (r.kind == storage::ReadingKind::kSample) samples.push_back(r);
    return Status::Ok();
  });
  if (scan.ok()) {
    scan = store_->ReplaceReadingUncertainties(session_, c.budgeter->EstimateSession(samples));
  }
  if (!scan.ok()) {
    spdlog::warn(
        "{}: the budgets estimated at commit are kept (estimating them again with the "
        "whole session failed: {})",
        where, scan.message());
  }
}

bool Executor::Load(Context& c, const std::string& where) {
  Result<storage::SessionRecord> session = store_->GetSession(session_);
  if (!session.ok()) {
    Stop(c, -1, session.status(), "reading " + where + " from the database", false);
    return false;
  }
  c.session = std::move(*session);
  Result<std::vector<storage::StepRecord>> steps = store_->GetSteps(session_);
  if (!steps.ok()) {
    Stop(c, -1, steps.status(), "reading the steps of " + where, false);
    return false;
  }
  c.steps = std::move(*steps);
  Result<std::shared_ptr<const SessionPlan>> plan = host_.Plan(session_);
  if (!plan.ok()) {
    Stop(c, -1, plan.status(), "reading the plan of " + where, false);
    return false;
  }
  c.settings = (*plan)->settings;
  c.sample_fixed = plan::SampleFixedMethod((*plan)->plan);
  c.adaptive = (*plan)->plan.has_adaptive();
  if (options_.uncertainty.has_value()) {
    c.budgeter.emplace(*options_.uncertainty, session_,
                       c.session.white_reflectance.value_or(kWhiteStandardReflectance),
                       plan::WhiteReflectanceSpectrumOf((*plan)->plan),
                       plan::WhiteReflectanceUncertaintyOf((*plan)->plan),
                       static_cast<int>(c.settings.measurement.averages));
  }
  TallySteps(c);
  // The latest reference and dark of the session so far: later samples are divided by them.
  Status scan = store_->ForEachReading(session_, [&c](const storage::ReadingRecord& r) {
    if (r.kind == storage::ReadingKind::kReference) c.last_reference = r.id;
    if (r.kind == storage::ReadingKind::kDark) c.last_dark = r.id;
    if (c.budgeter.has_value()) c.budgeter->Observe(r, r.recorded_at);
    return Status::Ok();
  });
  if (!scan.ok()) {
    Stop(c, -1, scan, "reading the readings of " + where, false);
    return false;
  }
  return true;
}

void Executor::TallySteps(Context& c) {
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
}

void Executor::RunSteps(Context& c) {
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
}

Status Executor::WithRetry(Context& c, int index, std::uint32_t first_attempt,
                           const std::function<Status(std::uint32_t attempt)>& attempt) {
  return RunWithRetry(
      c.settings.retry, first_attempt, *options_.clock, cancel_, attempt,
      [&](const Status& st, std::uint32_t n, std::uint32_t max_attempts, bool will_retry) {
        // A pose skipped on its overload gets its own fault event (SkipOverloadedPose), not the
        // one of a session that pauses.
        if (!will_retry && SkipsOverloadedPose(c, index, st)) return;
        host_.Fault(session_, FaultFor(index, st, n, will_retry, c.meter.last_quality));
        spdlog::warn("session {}: step {} attempt {}/{} failed: {}{}", session_, index, n,
                     max_attempts, st.ToString(), will_retry ? " (will retry)" : "");
      });
}

Executor::Outcome Executor::Stop(Context& c, int index, const Status& status,
                                 const std::string& what, bool reported) {
  if (cancel_.cancelled() || status.code() == StatusCode::kCancelled) return Outcome::kStop;
  const std::string reason = what + ": " + status.ToString();
  if (!reported) {
    host_.Fault(session_, FaultFor(index, status, 1, false, c.meter.last_quality, reason));
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
    if (attempt > 1) ResetStageAlarms(rig_, session_, ctx);
    c.stage.target.reset();
    BRDF_ASSIGN_OR_RETURN(Pose reached, MoveStageTo(rig_, step.pose, ctx));
    c.stage.target = step.pose;
    c.stage.feedback = reached;
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
    MutexLock lock(answer_mu_);
    answered_step_.reset();
  }
  Result<SessionState> state = host_.RaisePrompt(session_, prompt);
  if (!state.ok() || *state != SessionState::kAwaitingOperator) return Outcome::kStop;
  {
    MutexLock lock(answer_mu_);
    answer_cv_.Wait(answer_mu_, [&]() REQUIRES(answer_mu_) {
      return cancel_.cancelled() || (answered_step_.has_value() && *answered_step_ == index);
    });
  }
  if (cancel_.cancelled()) return Outcome::kStop;
  // The host stored the done mark and applied kAnswer (the session runs on).
  c.MarkDone(index);
  host_.StepCompleted(session_, Completion(c, index), nullptr);
  return Outcome::kContinue;
}

bool Executor::SkipsOverloadedPose(const Context& c, int index, const Status& failure) const {
  return c.adaptive &&
         c.steps[static_cast<std::size_t>(index)].kind == storage::StepKind::kSample &&
         failure.code() != StatusCode::kCancelled && !cancel_.cancelled() &&
         MeterOverloaded(rig_.meter_identity(), failure);
}

Executor::Outcome Executor::SkipOverloadedPose(Context& c, int index, const Status& failure) {
  const storage::StepRecord& step = c.steps[static_cast<std::size_t>(index)];
  const std::string note =
      "the meter overloaded at pose " + PoseText(step.pose) +
      " on every attempt, its quality policy's shorter integration included (" + failure.message() +
      ")";
  if (Status skipped = store_->SkipStep(session_, index, note); !skipped.ok()) {
    return Stop(c, index, skipped, "recording " + StepName(step) + " as skipped", false);
  }
  c.MarkDone(index, storage::StepState::kSkipped);
  const std::string reason = std::string(kSkippedFaultPrefix) + StepName(step) + ": " + note +
                             "; the adaptive session goes on without this pose, and its rounds "
                             "will not choose it again";
  const std::uint32_t attempts = std::max<std::uint32_t>(1, c.settings.retry.max_attempts);
  host_.Fault(session_, FaultFor(index, failure, attempts, false, c.meter.last_quality, reason));
  spdlog::warn("session {}: {}", session_, reason);
  return AfterStep(c);
}

ReadingRequest Executor::PlanReading(const Context& c, int index) {
  const storage::StepRecord& step = c.steps[static_cast<std::size_t>(index)];
  ReadingRequest request;
  request.step_index = index;
  request.step_name = StepName(step);
  request.pose = step.pose;
  // Where the stage must be: where the last move before this step put it. Sample-fixed plans
  // have no moves: the holder stays where it is.
  const int move_index = c.move_before[static_cast<std::size_t>(index)];
  if (move_index >= 0) request.required = c.steps[static_cast<std::size_t>(move_index)].pose;
  request.settings = MeterSettingsFor(c.settings.measurement, step.kind);

  const std::size_t next = static_cast<std::size_t>(index) + 1;
  const bool next_is_move = next < c.steps.size() &&
                            c.steps[next].kind == storage::StepKind::kMove &&
                            c.steps[next].state == storage::StepState::kPending;
  if (options_.pipelining && next_is_move &&
      host_.CurrentState(session_) == SessionState::kRunning) {
    request.pipelined_step = static_cast<int>(next);
    request.pipelined_pose = c.steps[next].pose;
  }
  return request;
}

Status Executor::CommitReading(Context& c, int index, storage::ReadingRecord& reading) {
  const double now = WallSeconds();
  if (c.budgeter.has_value() && reading.kind == storage::ReadingKind::kSample) {
    // Its uncertainty goes into the same transaction; one that cannot be estimated is stored
    // "not estimated" and the reading kept.
    Result<uncertainty::ReadingBudget> budget = c.budgeter->Estimate(reading, now);
    if (budget.ok()) {
      reading.uncertainty = std::move(*budget);
    } else {
      spdlog::debug("session {}: uncertainty of step {} not estimated: {}", session_, index,
                    budget.status().message());
    }
  }
  // The reading and the step's done mark in one transaction (the move, if pipelined, runs on).
  BRDF_ASSIGN_OR_RETURN(std::int64_t id, store_->CompleteStepWithReading(session_, index, reading));
  reading.id = id;
  reading.session_id = session_;
  reading.step_index = index;
  if (c.budgeter.has_value()) c.budgeter->Observe(reading, now);
  if (reading.kind == storage::ReadingKind::kReference) c.last_reference = id;
  if (reading.kind == storage::ReadingKind::kDark) c.last_dark = id;
  c.MarkDone(index);
  v1::StepCompletion done = Completion(c, index);
  done.set_reading_id(id);
  done.set_quality_code(reading.quality_code);
  done.set_flagged(reading.flagged);
  host_.StepCompleted(session_, done, &reading);
  return Status::Ok();
}

Executor::Outcome Executor::FinishPipelinedMove(Context& c, PipelinedMove& move, int& advanced) {
  move.Settle(c.stage);
  if (cancel_.cancelled()) return Outcome::kStop;
  const int move_step = move.step_index();
  const storage::StepRecord& step = c.steps[static_cast<std::size_t>(move_step)];
  const Status moved = move.status();
  if (moved.ok()) {
    // Only now, after the reading before it is committed, the move's done mark.
    if (Status marked = CompleteSimpleStep(c, move_step); !marked.ok()) {
      return Stop(c, move_step, marked, "recording " + StepName(step) + " as done", false);
    }
    advanced = 2;
    return Outcome::kContinue;
  }
  if (moved.code() == StatusCode::kCancelled) return Outcome::kStop;
  const std::uint32_t max_attempts = std::max<std::uint32_t>(1, c.settings.retry.max_attempts);
  const bool will_retry = Retryable(moved) && max_attempts > 1;
  host_.Fault(session_, FaultFor(move_step, moved, 1, will_retry, c.meter.last_quality));
  if (!will_retry) return Stop(c, move_step, moved, "moving the stage at " + StepName(step), true);
  c.next_move_first_attempt = 2;  // the loop runs the move next, as its second attempt
  return Outcome::kContinue;
}

Executor::Outcome Executor::RunReading(Context& c, int index, int& advanced) {
  advanced = 1;
  const storage::StepRecord& step = c.steps[static_cast<std::size_t>(index)];
  const ReadingRequest request = PlanReading(c, index);
  const ReadingDevices devices{rig_, session_, [this] { return DeviceContext(); }};
  PipelinedMove move;
  Result<TakenReading> taken = MeasureReading(
      devices, rig_.description(), request,
      [&](const std::function<Status(std::uint32_t)>& attempt) {
        return WithRetry(c, index, 1, attempt);
      },
      c.stage, c.meter, move);
  if (!taken.ok()) {
    move.Settle(c.stage);
    if (SkipsOverloadedPose(c, index, taken.status())) {
      return SkipOverloadedPose(c, index, taken.status());
    }
    return Stop(c, index, taken.status(), "taking the reading of " + StepName(step), true);
  }
  if (cancel_.cancelled()) {  // nothing is written after a cancel: resume redoes the step
    move.Settle(c.stage);
    return Outcome::kStop;
  }

  RecordSources sources;
  sources.sample_fixed = c.sample_fixed;
  sources.convention = rig_.description().convention;
  sources.reference = c.last_reference;
  sources.dark = c.last_dark;
  sources.meter = rig_.meter_identity();
  storage::ReadingRecord reading = BuildReadingRecord(step, std::move(*taken), sources);
  if (sources.meter.has_value()) RecordMeterOnce(*store_, c.session, *sources.meter, c.meter);

  if (Status committed = CommitReading(c, index, reading); !committed.ok()) {
    move.Settle(c.stage);
    return Stop(c, index, committed, "storing the reading of " + StepName(step), false);
  }
  if (move.started()) {
    if (FinishPipelinedMove(c, move, advanced) == Outcome::kStop) return Outcome::kStop;
  }
  return AfterStep(c);
}

}  // namespace brdf::daemon
