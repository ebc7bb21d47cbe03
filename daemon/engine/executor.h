// Executor: runs ONE session's stored steps on the rig, from its first unfinished step, following
// DESIGN.md ("The executor's rules"). It never decides a state on its own: every transition it
// causes (prompt, step done, fault, finish, error) goes through its host, which applies
// core/session_state.h's table, stores it and tells the watchers. When the host refuses a
// transition (the operator paused or aborted meanwhile) the executor stops.
//
// Per step:
//   move       MoveTo the step's pose (the motorized axes), retried per the plan's retry policy;
//              then its done mark.
//   prompt     the host raises the prompt (awaiting_operator) and the executor waits for
//              Answered(step) — the host marks the step done when the operator answers — or for
//              Cancel (pause, abort, shutdown).
//   reading    (reference, dark, sample) the stage must be where the last move before this step
//              put it (on resume it is moved there first); Configure the meter per the plan's
//              measurement settings, MeasureSpectrum (PR-650: M5, or M0 then D5), directions from
//              the pose (core/geometry; sample-fixed readings: the step's target), and one
//              transaction with the reading (naming the session's latest reference and dark) and
//              the done mark.
//
// Pipelining (Options::pipelining): when step k is a reading and step k+1 a move, the move starts
// on a second thread as soon as the meter has accepted the measurement of step k (MeasureSpectrum's
// callback: M5's status line, or M0's reply), while the spectrum transfers. Reading k is
// committed first, the move's done mark after it; a failed transfer waits for the move and moves
// back before measuring again. Not done while a deferred pause is pending.
//
// An adaptive session lives with a pose the meter cannot read: when a sample step of an adaptive
// plan fails on the meter's overload (quality 19, or the code a PR-670 or CS-2000 maps onto it)
// after the quality policy's shorter integration and the retry policy, the step is marked skipped
// with a note, a fault event (will_retry false, reason "step skipped: …" naming the pose) tells
// the watchers, and the session runs on. Fixed plans pause as below.
//
// Failures: a device call that fails is retried per the plan's retry policy (a fault event per
// failed attempt, with will_retry); when the attempts are used up, or the error cannot be cured by
// retrying (a pose beyond travel), the executor reports a fault and the session pauses with the
// error as its reason. A storage error pauses it too. Cancel (pause immediate, abort, shutdown)
// cancels the in-flight device calls and stops the stage; the step is not marked done, and the
// executor returns without touching the state (its canceller already set it). Nothing here
// throws; no device error can take the daemon down.
#pragma once

#include <chrono>
#include <cstdint>
#include <functional>
#include <memory>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "brdf/v1/brdf.pb.h"
#include "core/call_context.h"
#include "core/clock.h"
#include "core/mutex.h"
#include "core/plan/plan_settings.h"
#include "core/session_state.h"
#include "core/status.h"
#include "daemon/engine/reading_budget.h"
#include "daemon/engine/rig.h"
#include "daemon/sessions/session_plan.h"
#include "storage/records.h"
#include "storage/session_store.h"

namespace brdf::daemon {

struct ReadingRequest;  // engine_reading_step.h
class PipelinedMove;

// The start of the reason of the fault event a skipped step publishes (the session runs on).
inline constexpr std::string_view kSkippedFaultPrefix = "step skipped: ";

// What the executor needs from whoever runs it (the SessionManager). Called on the executor's
// thread.
class ExecutorHost {
 public:
  // Every stored step is done: the session goes on with steps the host has just stored (an
  // adaptive session's next round, adaptive_rounds.h), or it finishes with `finish_reason`.
  struct LastStepOutcome {
    bool more_steps = false;
    std::string finish_reason = "every step done";
  };

  virtual ~ExecutorHost() = default;
  // Asked each time every stored step is done, before the session finishes. An error stops the
  // run as a fault (the session pauses; resume asks again). Default: finish.
  virtual Result<LastStepOutcome> AfterLastStep(std::int64_t /*session*/) {
    return LastStepOutcome{};
  }
  // Applies an executor event (kStepDone, kFault, kFinish, kError) to the session: the state after
  // it, or the refusal (the session is no longer running: stop).
  virtual Result<SessionState> ApplyEvent(std::int64_t session, SessionEvent event,
                                          const std::string& reason) = 0;
  // The session's state now (to see a pending deferred pause).
  virtual SessionState CurrentState(std::int64_t session) = 0;
  // Raises a prompt: records it as the session's open prompt and applies kPrompt. Returns the
  // state after it (awaiting_operator; paused when a deferred pause was pending) or the refusal.
  virtual Result<SessionState> RaisePrompt(std::int64_t session, const v1::Prompt& prompt) = 0;
  // A step was committed. `reading` is the stored reading (with its id) for reading steps.
  virtual void StepCompleted(std::int64_t session, const v1::StepCompletion& completion,
                             const storage::ReadingRecord* reading) = 0;
  // A step failed (will_retry tells whether the executor tries again).
  virtual void Fault(std::int64_t session, const v1::Fault& fault) = 0;
  // The session's plan as the host keeps it (session_plan.h), or why it cannot be had (a stored
  // plan that no longer parses: the run stops with that reason).
  virtual Result<std::shared_ptr<const SessionPlan>> Plan(std::int64_t session) = 0;
};

class Executor {
 public:
  struct Options {
    // Move during the previous reading's spectrum transfer (DESIGN.md).
    bool pipelining = true;
    // Deadline of one device call (a move, a measurement with its transfer). The drivers have
    // tighter timeouts of their own; this only bounds a call that would otherwise hang.
    std::chrono::milliseconds device_call_timeout{std::chrono::minutes(10)};
    // Clock for device deadlines and retry backoff.
    const Clock* clock = &Clock::Real();
    // Each sample reading's uncertainty budget, stored with it (reading_budget.h); nullopt:
    // readings are stored "not estimated".
    std::optional<ReadingBudgetSettings> uncertainty;
  };

  Executor(std::int64_t session, std::shared_ptr<storage::SessionStore> store, Rig& rig,
           ExecutorHost& host, Options options);
  ~Executor();
  Executor(const Executor&) = delete;
  Executor& operator=(const Executor&) = delete;

  // Runs steps until the session finishes, pauses (deferred pause, fault, storage error), or the
  // run is cancelled. Blocks; call it on a thread of its own, once.
  void Run();

  // Cancels the in-flight device calls and any wait (pause immediate, abort, a pause while
  // awaiting the operator, shutdown) and stops the stage. Run returns soon after without
  // changing the session's state. Thread-safe; idempotent.
  void Cancel(const std::string& reason);

  // The operator answered the prompt of `step_index` (the host has marked the step done and
  // applied kAnswer). Thread-safe.
  void Answered(int step_index);

  std::int64_t session() const { return session_; }
  bool cancelled() const { return cancel_.cancelled(); }

 private:
  struct Context;  // per-run state (steps, settings, the latest reference/dark, …)
  enum class Outcome { kContinue, kStop };

  // The run's phases: the session, its steps and plan, the latest reference and dark read into
  // `c` (false, after stopping the run with the error, when the store fails); each step's
  // estimate and the progress so far; the pending steps run in order until one stops the run.
  bool Load(Context& c, const std::string& where);
  void TallySteps(Context& c);
  // Every stored step done: asks the host whether more were stored (then reads the steps again
  // and returns true, unless a pending pause or a refusal stops the run) or the session ends
  // (false, with the reason in `finish_reason`).
  bool MoreSteps(Context& c, const std::string& where, std::string& finish_reason);
  void RunSteps(Context& c);

  Outcome RunMove(Context& c, int index, std::uint32_t first_attempt);
  Outcome RunPrompt(Context& c, int index);
  // A reading step (engine_reading_step.h's handlers, then CommitReading and, when a move was
  // pipelined, FinishPipelinedMove). Returns how many steps were completed (1, or 2 with a
  // pipelined move) through `advanced`.
  Outcome RunReading(Context& c, int index, int& advanced);
  // Whether reading step `index` is skipped on `failure` (the retry policy used up): a sample
  // step of an adaptive plan whose meter overloaded (MeterOverloaded).
  bool SkipsOverloadedPose(const Context& c, int index, const Status& failure) const;
  // Marks the step skipped in the store with why (SessionStore::SkipStep), publishes a fault
  // event whose reason starts with kSkippedFaultPrefix and names the pose, and runs on
  // (AfterStep). The rounds never choose a skipped step's pose again (adaptive_rounds.h).
  Outcome SkipOverloadedPose(Context& c, int index, const Status& failure);
  // What measuring step `index` needs: its pose, where the stage must be, the meter's settings,
  // and the next step's move when it may be pipelined (pipelining on, the next step a pending
  // move, the session running).
  ReadingRequest PlanReading(const Context& c, int index);
  // The commit: the reading and the step's done mark in one transaction; then `reading` carries
  // its id, the session's latest reference / dark follow it, and the host hears of the completed
  // step with the reading. The store's error otherwise (nothing changed).
  Status CommitReading(Context& c, int index, storage::ReadingRecord& reading);
  // Every step done: each sample's budget estimated again with the whole session (its pose
  // through the neighbours, the drift to the next reference) and stored in one transaction. On
  // failure the budgets stored at commit stay (they name the pose "not estimated").
  void EstimateBudgetsAgain(Context& c, const std::string& where);
  // After the reading before it is committed: waits for the pipelined move; on success writes
  // its done mark (advanced = 2), on failure reports a fault and leaves the move for the loop to
  // run again as its second attempt, or stops when it may not be retried.
  Outcome FinishPipelinedMove(Context& c, PipelinedMove& move, int& advanced);

  // Runs `attempt` per the plan's retry policy (RunWithRetry); publishes a fault per failed
  // attempt.
  Status WithRetry(Context& c, int index, std::uint32_t first_attempt,
                   const std::function<Status(std::uint32_t attempt)>& attempt);
  // Commits a move's or prompt's done mark and publishes the completion.
  Status CompleteSimpleStep(Context& c, int index);
  // Applies kStepDone; kStop unless the session is still running.
  Outcome AfterStep(Context& c);
  // Ends the run on `status`: quietly when the run was cancelled, else (once `reported` or now)
  // a fault event and kFault (kError for an internal error) with the reason. Returns kStop.
  Outcome Stop(Context& c, int index, const Status& status, const std::string& what, bool reported);

  v1::StepCompletion Completion(const Context& c, int index) const;
  CallContext DeviceContext() const;

  const std::int64_t session_;
  std::shared_ptr<storage::SessionStore> store_;
  Rig& rig_;
  ExecutorHost& host_;
  Options options_;
  CancelToken cancel_;

  Mutex answer_mu_;
  CondVar answer_cv_;
  std::optional<int> answered_step_ GUARDED_BY(answer_mu_);
  bool wake_ GUARDED_BY(answer_mu_) = false;  // Cancel() or Answered() happened
};

}  // namespace brdf::daemon
