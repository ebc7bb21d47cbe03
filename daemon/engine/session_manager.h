// SessionManager: what the daemon does with sessions, as one object the gRPC services call. It
// submits plans (validate → expand → store, in one transaction with their steps), keeps the queue
// (one session on the rig at a time), carries out the operator's verbs through the state machine
// of core/session_state.h, runs the session that holds the rig on an Executor (executor.h), fans
// out events to watchers (event_bus.h) and, at start-up, parks sessions a dead daemon was driving
// as paused (Recover).
//
// Contract for the gRPC layer (daemon/service_*.cc):
//   - Session ids are storage's int64 ids; the API's string session_id is their decimal form
//     (ParseSessionId below parses it and names the field on error).
//   - Every verb returns the session as the API's brdf.v1.Session (the state after the call), or
//     a Status whose code maps one to one onto a gRPC code:
//       kInvalidArgument    → INVALID_ARGUMENT   (a plan with problems, a bad argument)
//       kNotFound           → NOT_FOUND          (no such session)
//       kFailedPrecondition → FAILED_PRECONDITION (not in this state; the message names the state
//                                                  and the verb, e.g. "cannot resume a session
//                                                  that is running")
//       kIoError            → UNAVAILABLE/INTERNAL (the database refused a write)
//       kInternal           → INTERNAL
//   - Every control verb (SubmitPlan, Start, Pause, Resume, Abort, AnswerPrompt) appends an audit
//     record with the caller's role and actor name (a token's NAME, never the token).
//   - All methods are thread-safe and return promptly: none waits for a device. Pause immediate
//     and Abort cancel the in-flight device call and return once the state is recorded; the
//     executor's thread winds down behind them.
//   - Watchers: Subscribe() gives a bounded queue per watcher whose first event is the session's
//     snapshot (plus the open prompt, when awaiting the operator); a slow watcher loses old events
//     (sequence numbers then skip), it never slows the executor.
//   - The rig and the queue: the session that last went RUNNING holds the rig until it ends
//     (completed, aborted, failed) — also while it is paused or awaits the operator, so that
//     pausing for the lamp never lets the next session start on the wrong sample (as Bluesky's
//     queue server does). Start (or Resume of another session) meanwhile leaves the session
//     QUEUED, in order; the head of the queue starts by itself when the holder ends. After a
//     restart the rig is held by the first recovered session; the queue is not rebuilt (sessions
//     that were waiting stay QUEUED until started again): nothing starts by itself after a crash.
//   - Readings: AddReadingListener() callbacks run on the executor's thread right after each
//     reading is committed (the index cache subscribes); they must be quick and must not call
//     back into the manager's verbs.
#pragma once

#include <atomic>
#include <chrono>
#include <cstdint>
#include <functional>
#include <memory>
#include <mutex>
#include <optional>
#include <string>
#include <vector>

#include "brdf/v1/brdf.pb.h"
#include "core/clock.h"
#include "core/plan/analyze_plan.h"
#include "core/plan/problem.h"
#include "core/plan/rig_description.h"
#include "core/session_state.h"
#include "core/status.h"
#include "daemon/engine/adaptive_rounds.h"
#include "daemon/engine/event_bus.h"
#include "daemon/engine/reading_budget.h"
#include "daemon/engine/rig.h"
#include "daemon/sessions/pause_mode.h"
#include "daemon/sessions/session_id.h"
#include "daemon/sessions/session_plan.h"
#include "storage/records.h"
#include "storage/session_store.h"

namespace brdf::daemon {

class Executor;

// Called after a reading is committed: (session, the stored reading with its id). The record is
// the one the executor committed, complete for deriving from it (kind, pose, directions, grid,
// spectrum, the reference and dark it names); only recorded_at is left 0 (the store's clock).
using ReadingListener = std::function<void(SessionId, const storage::ReadingRecord&)>;

class SessionManager {
 public:
  struct Options {
    // The rig as the plan code sees it (axes, travel limits, timing model): plans are validated
    // and expanded against it. The daemon fills it from its configuration.
    plan::RigDescription rig_description;
    // White standard's reflectance stored with every session (ρw, the paper's 0.99).
    double white_reflectance = 0.99;
    // The rig's name, stored with every session (config [rig] name, default the host name).
    std::string rig_name;
    // GetRigStatus's archive part (ArchiveShipper::Snapshot); unset: shipping is off.
    std::function<v1::ArchiveStatus()> archive_status;
    // Move to the next pose while the meter transfers the previous spectrum (DESIGN.md). Off only
    // for benchmarks comparing the two.
    bool pipelining = true;
    // Bounded queue per watcher (events).
    std::size_t watcher_queue_capacity = 256;
    // Clock for waits (retry backoff) and device deadlines; tests may scale it.
    const Clock* clock = &Clock::Real();
    // Each sample reading's uncertainty budget (reading_budget.h); nullopt: not estimated.
    std::optional<ReadingBudgetSettings> uncertainty;
    // The uncertainty model adaptive sessions choose their rounds by (adaptive_rounds.h); unset:
    // adaptive plans are refused (SubmitPlan, Start: kFailedPrecondition).
    UncertaintyModelFactory uncertainty_model;
  };

  // Takes a shared store (the Data service and the index cache read it too) and the rig. Starts
  // the rig's supervisor (devices connect in the background) and the queue's scheduler thread;
  // no session runs until a verb asks for it. Shutdown closes the devices.
  SessionManager(std::shared_ptr<storage::SessionStore> store, std::shared_ptr<Rig> rig,
                 Options options);
  // Shutdown(), if not called before.
  ~SessionManager();
  SessionManager(const SessionManager&) = delete;
  SessionManager& operator=(const SessionManager&) = delete;

  // --- Start-up and shutdown ------------------------------------------------------------------

  // Call once at start-up, before serving: sessions a dead daemon left running, pausing or
  // awaiting the operator become paused (reason storage::kRecoveredReason); each resumes, when
  // the operator says so, at its first unfinished step. Returns their ids. Queued sessions stay
  // queued (nothing starts by itself after a restart).
  Result<std::vector<SessionId>> Recover();

  // SIGTERM/SIGINT: deferred pause of the running session, wait up to `timeout` for the step in
  // progress to finish (then cancel it: an immediate pause), stop the rig's supervisor and close
  // the devices. Afterwards every verb fails with kFailedPrecondition. Idempotent.
  void Shutdown(std::chrono::milliseconds timeout = std::chrono::seconds(60));

  // --- Plans ----------------------------------------------------------------------------------

  // Checks and summarises a plan against this rig; stores nothing. The gRPC layer turns it into
  // a ValidatePlanResponse (wire/plan.h: ToValidatePlanResponse). The summary's times are for a rig
  // whose devices run `time_scale` (> 0) times faster (plan::AnalyzePlan); 0: this rig's own
  // (Options.rig_description.time_scale, the configuration's [rig] time_scale).
  plan::PlanAnalysis ValidatePlan(const v1::Plan& plan, double time_scale = 0) const;

  // Validates, expands and stores the plan as a new QUEUED session (then starts it when
  // `start_now`, as Start would). A plan with problems: kInvalidArgument whose message lists
  // every problem as "<field_path>: <message>" lines, and `problems` (when given) receives them
  // as data. Audit: "session.submit".
  Result<v1::Session> SubmitPlan(const v1::Plan& plan, const Actor& actor, bool start_now = false,
                                 std::vector<plan::Problem>* problems = nullptr);

  // --- Operator verbs (each audited: "session.start", "session.pause", …) ---------------------

  // QUEUED → RUNNING when the rig is free, else it stays QUEUED (in the queue, in order of
  // Start calls) and runs when the rig frees. Starting a session already waiting in the queue is
  // a no-op that returns it.
  Result<v1::Session> Start(SessionId session, const Actor& actor);
  // RUNNING → PAUSING (deferred) or PAUSED (immediate); AWAITING_OPERATOR → PAUSED. Pausing a
  // paused session is a no-op; immediate upgrades a pausing one. `already_paused` (when given)
  // says whether the session was PAUSED before the call, from the manager's state under the
  // same lock as the verb (no store read).
  Result<v1::Session> Pause(SessionId session, PauseMode mode, const Actor& actor,
                            bool* already_paused = nullptr);
  // PAUSED (or PAUSING: cancels the pending pause) → RUNNING, or QUEUED when another session
  // holds the rig. The step cancelled by an immediate pause, or that faulted, is run again, after
  // moving the stage to the pose of the first unfinished step.
  Result<v1::Session> Resume(SessionId session, const Actor& actor);
  // Any non-terminal state → ABORTED, keeping every reading. Cancels the in-flight call and stops
  // the stage when the session is on the rig. `reason` is stored with the session.
  Result<v1::Session> Abort(SessionId session, const std::string& reason, const Actor& actor);
  // Confirms the pending prompt. `step_index` must be the pending prompt's (Prompt.step_index),
  // else kFailedPrecondition (a late or repeated answer never confirms the next prompt). `note`
  // goes to the audit log. The prompt step is marked done and the session runs on.
  Result<v1::Session> AnswerPrompt(SessionId session, int step_index, const std::string& note,
                                   const Actor& actor);

  // --- Queries --------------------------------------------------------------------------------

  // One session with its plan, summary, progress, ETA, current step, pending prompt, last fault
  // and last quality code. kNotFound when there is no such session.
  Result<v1::Session> GetSession(SessionId session) const;
  // Every session, newest first, without the plan (Session.plan left empty); optionally only
  // those in `states` (empty: all). Paging is the caller's.
  Result<std::vector<v1::Session>> ListSessions(const std::vector<SessionState>& states = {}) const;
  // The rig's devices, live pose and meter serial, plus which session holds the rig.
  v1::RigStatus GetRigStatus() const;
  // The session's state as the manager knows it (no store read once the session is known).
  // kNotFound when there is no such session.
  Result<SessionState> State(SessionId session) const;
  // How many times a session reached a terminal state (any session), without the manager's lock:
  // a following stream asks State (which takes the lock the verbs take) only when this moved
  // since it last asked, so analysts' streams never hold up the operator's verbs.
  std::uint64_t endings() const { return endings_.load(); }
  // The session's plan, parsed once (at submission, or when the session is first loaded) and
  // kept with the session (session_plan.h). kNotFound when there is no such session; kInternal
  // "session N: its stored plan does not parse: …" (logged once) when its stored plan is
  // unreadable.
  Result<std::shared_ptr<const SessionPlan>> Plan(SessionId session) const;

  // --- Watching -------------------------------------------------------------------------------

  // A watcher of one session: first a snapshot (SessionEvent.snapshot) and, when the session is
  // awaiting the operator, its open prompt; then every state change, prompt, step completion and
  // fault; the subscription ends after the session reaches a terminal state (see
  // EventSubscription::Next). kNotFound when there is no such session.
  Result<std::shared_ptr<EventSubscription>> Subscribe(SessionId session);

  // Registers a callback for every reading committed from now on (any session). Returns a handle
  // for RemoveReadingListener.
  int AddReadingListener(ReadingListener listener);
  void RemoveReadingListener(int handle);

  // The store, for read-only services (Data) that share it.
  const std::shared_ptr<storage::SessionStore>& store() const { return store_; }
  const Options& options() const { return options_; }

 private:
  struct Impl;
  std::shared_ptr<storage::SessionStore> store_;
  std::shared_ptr<Rig> rig_;
  Options options_;
  std::atomic<std::uint64_t> endings_{0};
  std::unique_ptr<Impl> impl_;
};

}  // namespace brdf::daemon
