#include "daemon/engine/session_manager.h"

#include <spdlog/spdlog.h>

#include <algorithm>
#include <cctype>
#include <deque>
#include <map>
#include <thread>
#include <utility>

#include "core/mutex.h"
#include "core/plan/plan_json.h"
#include "core/plan/plan_settings.h"
#include "core/plan/plan_summary.h"
#include "core/plan/sample.h"
#include "core/plan/timing.h"
#include "daemon/engine/audit_writer.h"
#include "daemon/engine/executor.h"
#include "daemon/wire/enums.h"
#include "daemon/wire/plan.h"
#include "daemon/wire/session.h"

namespace brdf::daemon {
namespace {

// Adaptive sessions choose their rounds by an uncertainty model (Options::uncertainty_model).
constexpr const char* kNoUncertaintyModel =
    "no uncertainty model is configured in this daemon, so it cannot choose the rounds of an "
    "adaptive plan (it validates and estimates); run the plan on a daemon that has one";

std::string Who(const Actor& actor) {
  std::string who = actor.name.empty() ? std::string("anonymous") : actor.name;
  if (!actor.role.empty()) who += " (" + actor.role + ")";
  return who;
}

std::string SessionName(SessionId id) {
  return "session " + std::to_string(id);
}

}  // namespace

// Everything the manager keeps in memory. All fields are guarded by `mu`; every state change and
// every event is made under it, so watchers see events in the order of the changes.
struct SessionManager::Impl final : public ExecutorHost {
  struct Live {
    std::optional<SessionState> state;  // cached; the store holds the truth
    std::optional<v1::Prompt> prompt;   // open while awaiting the operator
    std::optional<v1::Fault> last_fault;
    int last_quality = -1;
    std::string pause_reason;  // why a deferred pause was asked (used when it takes effect)
    std::string reason;        // why it is in `state` (what the store holds, also when it failed)
  };

  Impl(SessionManager& owner_in, storage::SessionStore& store_in, Rig& rig_in)
      : owner(owner_in),
        store(store_in),
        rig(rig_in),
        bus(owner_in.options_.watcher_queue_capacity) {}

  // --- ExecutorHost (called on the executor's thread) -----------------------------------------

  Result<SessionState> ApplyEvent(std::int64_t session, SessionEvent event,
                                  const std::string& reason) override {
    MutexLock lock(mu);
    return TransitionLocked(session, event, reason);
  }

  SessionState CurrentState(std::int64_t session) override {
    MutexLock lock(mu);
    Result<SessionState> s = StateLocked(session);
    return s.ok() ? *s : SessionState::kFailed;
  }

  Result<SessionState> RaisePrompt(std::int64_t session, const v1::Prompt& prompt) override {
    MutexLock lock(mu);
    Result<SessionState> next = TransitionLocked(session, SessionEvent::kPrompt,
                                                 "waiting for the operator: " + prompt.text());
    if (next.ok() && *next == SessionState::kAwaitingOperator) {
      live[session].prompt = prompt;
      v1::SessionEvent event;
      *event.mutable_prompt() = prompt;
      bus.Publish(session, std::move(event));
    }
    return next;
  }

  void StepCompleted(std::int64_t session, const v1::StepCompletion& completion,
                     const storage::ReadingRecord* reading) override {
    {
      MutexLock lock(mu);
      if (reading != nullptr) live[session].last_quality = reading->quality_code;
      v1::SessionEvent event;
      *event.mutable_step_completed() = completion;
      bus.Publish(session, std::move(event));
    }
    if (reading == nullptr) return;
    std::vector<ReadingListener> to_call;
    {
      MutexLock lock(listeners_mu);
      for (const auto& [handle, fn] : listeners) to_call.push_back(fn);
    }
    for (const ReadingListener& fn : to_call) fn(session, *reading);
  }

  Result<std::shared_ptr<const SessionPlan>> Plan(std::int64_t session) override {
    MutexLock lock(mu);
    return PlanLocked(session, nullptr);
  }

  Result<LastStepOutcome> AfterLastStep(std::int64_t session) override {
    BRDF_ASSIGN_OR_RETURN(std::shared_ptr<const SessionPlan> kept, Plan(session));
    if (!kept->plan.has_adaptive()) return LastStepOutcome{};
    return NextAdaptiveRound(session, kept->plan);
  }

  // An adaptive session's next round stored (more steps) or its stop (the finish reason); either
  // is published to the watchers.
  Result<LastStepOutcome> NextAdaptiveRound(SessionId id, const v1::Plan& plan) {
    if (!owner.options_.uncertainty_model) return FailedPrecondition(kNoUncertaintyModel);
    const adaptive::AdaptiveSpec spec = adaptive::ResolveAdaptive(plan.adaptive());
    std::unique_ptr<adaptive::UncertaintyModel> model = owner.options_.uncertainty_model(spec);
    if (model == nullptr) return Internal("the uncertainty model factory made no model");
    BRDF_ASSIGN_OR_RETURN(RoundDecision decision,
                          NextRound(store, id, plan, owner.options_.rig_description, *model));
    LastStepOutcome out;
    v1::SessionEvent event;
    if (decision.round.has_value()) {
      *event.mutable_adaptive_round() =
          ToProtoRound(*decision.round, {decision.spent, decision.round_cost});
      out.more_steps = true;
      spdlog::info(
          "{}: round {} stored: {} poses, {} steps, predicted gain {:.4g}, uncertainty "
          "left {:.4g}",
          SessionName(id), decision.round->round, decision.round->picks.size(),
          decision.round->step_count, decision.round->predicted_gain, decision.uncertainty_left);
    } else {
      *event.mutable_adaptive_stop() = ToProtoStop(decision);
      out.finish_reason = StopText(decision, spec);
    }
    MutexLock lock(mu);
    bus.Publish(id, std::move(event));
    return out;
  }

  void Fault(std::int64_t session, const v1::Fault& fault) override {
    MutexLock lock(mu);
    live[session].last_fault = fault;
    if (fault.last_quality_code() >= 0) live[session].last_quality = fault.last_quality_code();
    v1::SessionEvent event;
    *event.mutable_fault() = fault;
    bus.Publish(session, std::move(event));
  }

  // --- State --------------------------------------------------------------------------------

  Result<SessionState> StateLocked(SessionId id) REQUIRES(mu) {
    Live& l = live[id];
    if (l.state.has_value()) return *l.state;
    Result<storage::SessionRecord> rec = store.GetSession(id);
    if (!rec.ok()) {
      live.erase(id);
      return rec.status();
    }
    l.state = rec->state;
    return rec->state;
  }

  // The rig is free for `id` when nobody holds it (or `id` does) and no session waits before it.
  bool RigFreeFor(SessionId id) const REQUIRES(mu) {
    if (holder.has_value() && *holder != id) return false;
    return queue.empty() || queue.front() == id;
  }

  // The one place where a session's state changes: core/session_state.h's table, then the store,
  // then the watchers.
  Result<SessionState> TransitionLocked(SessionId id, SessionEvent event, std::string reason)
      REQUIRES(mu) {
    BRDF_ASSIGN_OR_RETURN(SessionState from, StateLocked(id));
    Result<SessionState> to = NextState(from, event, RigFreeFor(id));
    if (!to.ok()) return Status(to.status().code(), SessionName(id) + ": " + to.status().message());
    Live& l = live[id];
    if (*to == SessionState::kPaused && reason.empty()) {
      reason = l.pause_reason.empty() ? "paused after the step in progress" : l.pause_reason;
    }
    if (*to == SessionState::kQueued && !holder.has_value()) {
      reason = "waiting for the rig (" + std::to_string(queue.size()) +
               " session(s) before it); it starts by itself when the rig is free";
    } else if (*to == SessionState::kQueued) {
      const Result<SessionState> holding = StateLocked(*holder);
      const bool held_paused = holding.ok() && *holding == SessionState::kPaused;
      reason = "waiting for the rig (" + SessionName(*holder) +
               (held_paused ? " holds it, paused: it frees the rig once it ends, so resume or "
                              "abort it"
                            : " holds it") +
               "); it starts by itself when the rig is free";
    }
    if (*to == SessionState::kQueued && from == SessionState::kQueued &&
        std::find(queue.begin(), queue.end(), id) == queue.end()) {
      // Started while the rig is busy: the session joins the queue (state unchanged).
      BRDF_RETURN_IF_ERROR(store.SetSessionState(id, *to, reason));
      live[id].reason = reason;
      queue.push_back(id);
      spdlog::info("{}: queued ({})", SessionName(id), reason);
      return *to;
    }
    if (*to == from) return *to;  // idempotent (pause while paused, start while queued)

    if (Status stored = store.SetSessionState(id, *to, reason); !stored.ok()) {
      // The database refuses writes (disk full, read-only file). A pause must still happen: the
      // executor has stopped, and a session left "running" with nothing running could never be
      // resumed. It is kept in memory until a later transition writes the state; a crash
      // meanwhile leaves "running" in the file, which recovery turns into paused anyway.
      if (*to != SessionState::kPaused || stored.code() != StatusCode::kIoError) return stored;
      spdlog::error("{}: paused, but the database did not record it: {}", SessionName(id),
                    stored.ToString());
    }
    l.state = *to;
    l.reason = reason;
    if (*to != SessionState::kAwaitingOperator) l.prompt.reset();
    if (*to == SessionState::kRunning) {
      holder = id;
      l.pause_reason.clear();
    }
    if (*to == SessionState::kQueued) {
      if (std::find(queue.begin(), queue.end(), id) == queue.end()) queue.push_back(id);
    } else {
      queue.erase(std::remove(queue.begin(), queue.end(), id), queue.end());
    }
    if (IsTerminal(*to) && holder == id) holder.reset();
    if (IsTerminal(*to)) {
      l.prompt.reset();
      owner.endings_.fetch_add(1);
    }

    v1::SessionEvent change;
    change.mutable_state_changed()->set_from(ToProtoState(from));
    change.mutable_state_changed()->set_to(ToProtoState(*to));
    change.mutable_state_changed()->set_reason(reason);
    bus.Publish(id, std::move(change), IsTerminal(*to));
    spdlog::info("{}: {} -> {} ({}){}", SessionName(id), SessionStateName(from),
                 SessionStateName(*to), SessionEventName(event),
                 reason.empty() ? "" : ": " + reason);
    scheduler_cv.NotifyAll();
    return *to;
  }

  // --- The session's plan -------------------------------------------------------------------

  // The plan kept with the session, parsed from `record` (read from the store when null) the
  // first time it is asked for. A plan that does not parse is logged once and kept as its Status.
  Result<std::shared_ptr<const SessionPlan>> PlanLocked(SessionId id,
                                                        const storage::SessionRecord* record)
      REQUIRES(mu) {
    auto kept = plans.find(id);
    if (kept != plans.end()) return kept->second;
    storage::SessionRecord read;
    if (record == nullptr) {
      BRDF_ASSIGN_OR_RETURN(read, store.GetSession(id));
      record = &read;
    }
    Result<SessionPlan> parsed = ParseSessionPlan(*record);
    if (!parsed.ok()) spdlog::error("{}", parsed.status().message());
    Result<std::shared_ptr<const SessionPlan>> plan =
        parsed.ok() ? Result<std::shared_ptr<const SessionPlan>>(
                          std::make_shared<const SessionPlan>(std::move(*parsed)))
                    : Result<std::shared_ptr<const SessionPlan>>(parsed.status());
    plans.emplace(id, plan);
    return plan;
  }

  // --- The session as the API shows it ------------------------------------------------------

  Result<v1::Session> BuildLocked(SessionId id, bool with_plan) REQUIRES(mu) {
    if (!with_plan) {
      auto cached = terminal_cache.find(id);
      if (cached != terminal_cache.end()) return cached->second;
    }
    BRDF_ASSIGN_OR_RETURN(storage::SessionRecord rec, store.GetSession(id));
    BRDF_ASSIGN_OR_RETURN(std::vector<storage::StepRecord> steps, store.GetSteps(id));
    const Live& l = live[id];
    const SessionState state = l.state.value_or(rec.state);

    // A plan that no longer parses is shown as none (PlanLocked logged it once); its summary and
    // ETA are the default settings'.
    static const SessionPlan kNoPlan = MakeSessionPlan(v1::Plan());
    Result<std::shared_ptr<const SessionPlan>> kept = PlanLocked(id, &rec);
    const plan::PlanSettings& settings = kept.ok() ? (*kept)->settings : kNoPlan.settings;
    const std::vector<plan::Step> plan_steps = ToPlanSteps(steps);
    const plan::PlanSummary summary =
        plan::SummarizeSteps(plan_steps, owner.options_.rig_description, settings.measurement);
    const std::vector<plan::StepTime> times =
        plan::EstimateSteps(plan_steps, owner.options_.rig_description, settings.measurement);
    double eta = 0;
    for (std::size_t i = 0; i < steps.size() && i < times.size(); ++i) {
      if (steps[i].state == storage::StepState::kPending) eta += times[i].estimate_s;
    }

    SessionFacts facts(rec);
    facts.live_state = l.state;
    facts.live_reason = l.reason;
    facts.plan = kept.ok() ? kept->get() : nullptr;
    facts.with_plan = with_plan;
    facts.steps = &steps;
    facts.summary = &summary;
    // A queued session has no running ETA: it has not started (or waits for another session).
    facts.eta_s = IsTerminal(state) || state == SessionState::kQueued ? 0 : eta;
    facts.pending_prompt = l.prompt.has_value() ? &*l.prompt : nullptr;
    facts.last_fault = l.last_fault.has_value() ? &*l.last_fault : nullptr;
    facts.last_quality_code = l.last_quality;
    v1::Session s = ToProtoSession(facts);
    if (IsTerminal(state) && !with_plan) terminal_cache[id] = s;
    return s;
  }

  // --- Audit --------------------------------------------------------------------------------

  // The record, durable when this returns (`later`: written by the audit writer's thread right
  // after; audit_writer.h says which verbs).
  void Audit(const Actor& actor, const std::string& action, std::optional<SessionId> session,
             const std::string& detail, bool later = false) {
    storage::AuditRecord record;
    record.role = actor.role;
    record.actor = actor.name;
    record.action = action;
    record.session_id = session;
    record.detail = detail;
    later ? audit.WriteLater(std::move(record)) : audit.Write(std::move(record));
  }

  // Runs a verb under the lock and audits it, successful or refused. A refused verb, or one whose
  // body set `*changed_nothing` (when given), is answered before its record is written.
  Result<v1::Session> Verb(SessionId id, const Actor& actor, const std::string& action,
                           const std::string& detail, const std::function<Status()>& body,
                           const bool* changed_nothing = nullptr) {
    Status st;
    Result<v1::Session> out = Internal("unset");
    {
      MutexLock lock(mu);
      if (shut_down) {
        st = FailedPrecondition("the daemon is shutting down; try again after it restarts");
      } else {
        st = body();
      }
      if (st.ok()) out = BuildLocked(id, /*with_plan=*/true);
    }
    const bool later = !st.ok() || (changed_nothing != nullptr && *changed_nothing);
    Audit(actor, action, id, st.ok() ? detail : "refused: " + st.ToString(), later);
    if (!st.ok()) return st;
    return out;
  }

  // --- Runs ---------------------------------------------------------------------------------

  // Starts an executor for `id` (scheduler thread, mu held, no other run alive).
  void LaunchLocked(SessionId id) REQUIRES(mu) {
    Executor::Options options;
    options.pipelining = owner.options_.pipelining;
    options.clock = owner.options_.clock;
    options.uncertainty = owner.options_.uncertainty;
    auto executor = std::make_shared<Executor>(id, owner.store_, rig, *this, options);
    current = executor;
    running_thread = std::thread([this, executor] {
      executor->Run();
      MutexLock lock(mu);
      if (current == executor) current.reset();
      run_ended = true;
      scheduler_cv.NotifyAll();
    });
  }

  void Schedule() {
    MutexLock lock(mu);
    for (;;) {
      scheduler_cv.Wait(mu, [this]() REQUIRES(mu) {
        return stopping || run_ended || (!current && launch.has_value()) ||
               (!holder.has_value() && !queue.empty() && !shut_down);
      });
      if (run_ended) {
        run_ended = false;
        std::thread finished = std::move(running_thread);
        lock.Unlock();
        if (finished.joinable()) finished.join();
        lock.Lock();
      }
      if (stopping && !current) return;
      if (!holder.has_value() && !queue.empty() && !shut_down) {
        const SessionId next = queue.front();
        Result<SessionState> started =
            TransitionLocked(next, SessionEvent::kStart, "the rig is free");
        if (!started.ok()) {
          spdlog::warn("{}: could not start from the queue: {}", SessionName(next),
                       started.status().ToString());
          queue.erase(std::remove(queue.begin(), queue.end(), next), queue.end());
        } else if (*started == SessionState::kRunning) {
          launch = next;
        }
      }
      if (!current && launch.has_value() && !running_thread.joinable() && !shut_down) {
        const SessionId id = *launch;
        launch.reset();
        Result<SessionState> state = StateLocked(id);
        if (state.ok() && (*state == SessionState::kRunning || *state == SessionState::kPausing)) {
          LaunchLocked(id);
        }
      } else if (shut_down) {
        launch.reset();
      }
    }
  }

  // After a verb made `id` running: a new run starts once the previous one (if any, e.g. one
  // winding down after an immediate pause) has ended.
  void EnsureRunLocked(SessionId id) REQUIRES(mu) {
    launch = id;
    scheduler_cv.NotifyAll();
  }

  SessionManager& owner;
  storage::SessionStore& store;
  Rig& rig;
  EventBus bus;
  AuditWriter audit{
      store, [] {
        return std::chrono::duration<double>(std::chrono::system_clock::now().time_since_epoch())
            .count();
      }};

  Mutex mu;
  CondVar scheduler_cv;
  std::map<SessionId, Live> live GUARDED_BY(mu);
  // Terminal sessions without their plan.
  std::map<SessionId, v1::Session> terminal_cache GUARDED_BY(mu);
  // Each session's plan, parsed once (PlanLocked), or why it does not parse.
  std::map<SessionId, Result<std::shared_ptr<const SessionPlan>>> plans GUARDED_BY(mu);
  std::deque<SessionId> queue GUARDED_BY(mu);        // started, waiting for the rig, in order
  std::optional<SessionId> holder GUARDED_BY(mu);    // the session that holds the rig
  std::optional<SessionId> launch GUARDED_BY(mu);    // a run to start once no run is alive
  std::shared_ptr<Executor> current GUARDED_BY(mu);  // the run alive (maybe winding down)
  // Its thread: set and taken under mu; joined by Shutdown once the scheduler has ended.
  std::thread running_thread;
  bool run_ended GUARDED_BY(mu) = false;
  bool shut_down GUARDED_BY(mu) = false;  // verbs refused
  bool stopping GUARDED_BY(mu) = false;   // the scheduler ends
  std::thread scheduler;

  Mutex listeners_mu;
  std::map<int, ReadingListener> listeners GUARDED_BY(listeners_mu);
  int next_listener GUARDED_BY(listeners_mu) = 1;
};

SessionManager::SessionManager(std::shared_ptr<storage::SessionStore> store,
                               std::shared_ptr<Rig> rig, Options options)
    : store_(std::move(store)), rig_(std::move(rig)), options_(std::move(options)) {
  impl_ = std::make_unique<Impl>(*this, *store_, *rig_);
  rig_->Start();
  impl_->scheduler = std::thread([this] { impl_->Schedule(); });
}

SessionManager::~SessionManager() {
  Shutdown(std::chrono::seconds(10));
}

Result<std::vector<SessionId>> SessionManager::Recover() {
  BRDF_ASSIGN_OR_RETURN(std::vector<std::int64_t> ids, store_->RecoverInterruptedSessions());
  {
    MutexLock lock(impl_->mu);
    for (SessionId id : ids) impl_->live[id].state = SessionState::kPaused;
    if (!ids.empty() && !impl_->holder.has_value()) impl_->holder = ids.front();
  }
  for (SessionId id : ids) {
    spdlog::warn(
        "{}: was running when the daemon stopped; now paused at its first unfinished "
        "step (resume it to go on)",
        SessionName(id));
    impl_->Audit(Actor{"daemon", "brdfd"}, "session.recover", id,
                 std::string(storage::kRecoveredReason));
  }
  return std::vector<SessionId>(ids.begin(), ids.end());
}

void SessionManager::Shutdown(std::chrono::milliseconds timeout) {
  Impl& m = *impl_;
  MutexLock lock(m.mu);
  if (m.stopping) return;
  m.shut_down = true;
  m.queue.clear();  // nothing new starts; waiting sessions stay QUEUED in the store
  m.launch.reset();
  // A deferred pause of the session on the rig: its step in progress finishes.
  if (m.current && !m.current->cancelled()) {
    const SessionId id = m.current->session();
    Result<SessionState> state = m.StateLocked(id);
    if (state.ok() && (*state == SessionState::kRunning || *state == SessionState::kPausing ||
                       *state == SessionState::kAwaitingOperator)) {
      m.live[id].pause_reason = "daemon shutting down (paused after the step in progress)";
      Result<SessionState> paused =
          m.TransitionLocked(id, SessionEvent::kPauseDeferred, m.live[id].pause_reason);
      if (paused.ok() && *paused == SessionState::kPaused)
        m.current->Cancel("daemon shutting down");
    }
  }
  if (!m.scheduler_cv.WaitFor(m.mu, timeout, [&m]() REQUIRES(m.mu) { return !m.current; })) {
    // The step did not finish in time: cancel it (resume redoes it).
    const SessionId id = m.current->session();
    spdlog::warn("{}: step still running at shutdown after {} ms; cancelling it", SessionName(id),
                 timeout.count());
    (void)m.TransitionLocked(id, SessionEvent::kPauseImmediate,
                             "daemon shutting down (step in progress cancelled; resume redoes it)");
    m.current->Cancel("daemon shutting down");
    m.scheduler_cv.Wait(m.mu, [&m]() REQUIRES(m.mu) { return !m.current; });
  }
  m.stopping = true;
  m.scheduler_cv.NotifyAll();
  lock.Unlock();
  if (m.scheduler.joinable()) m.scheduler.join();
  if (m.running_thread.joinable()) m.running_thread.join();
  m.audit.Drain();  // the records of verbs answered before their record was written
  rig_->Stop();
}

plan::PlanAnalysis SessionManager::ValidatePlan(const v1::Plan& plan, double time_scale) const {
  return plan::AnalyzePlan(plan, options_.rig_description,
                           time_scale > 0 ? time_scale : options_.rig_description.time_scale);
}

Result<v1::Session> SessionManager::SubmitPlan(const v1::Plan& plan, const Actor& actor,
                                               bool start_now,
                                               std::vector<plan::Problem>* problems) {
  plan::PlanAnalysis analysis =
      plan::AnalyzePlan(plan, options_.rig_description, options_.rig_description.time_scale);
  if (!analysis.valid()) {
    const std::string listing = plan::FormatProblems(analysis.problems);
    if (problems != nullptr) *problems = analysis.problems;
    impl_->Audit(actor, "session.submit", std::nullopt,
                 "refused: " + std::to_string(analysis.problems.size()) + " problem(s) in plan \"" +
                     plan.name() + "\"");
    return InvalidArgument("the plan has " + std::to_string(analysis.problems.size()) +
                           " problem(s); fix them and submit again:\n" + listing);
  }
  if (plan.has_adaptive() && !options_.uncertainty_model) {
    impl_->Audit(actor, "session.submit", std::nullopt,
                 "refused: plan \"" + plan.name() +
                     "\" is adaptive and no uncertainty model is "
                     "configured");
    return FailedPrecondition(kNoUncertaintyModel);
  }
  BRDF_ASSIGN_OR_RETURN(std::string json, plan::PlanToJson(plan));

  storage::NewSession session;
  session.name = plan.name().empty() ? std::string("unnamed plan") : plan.name();
  session.plan_kind = PlanKindWord(plan);
  session.plan_json = std::move(json);
  session.created_by_role = actor.role;
  session.white_reflectance = plan::WhiteReflectanceOf(plan).value_or(options_.white_reflectance);
  session.rig = options_.rig_name;
  if (std::optional<drivers::MeterIdentity> id = rig_->meter_identity(); id.has_value()) {
    session.meter_serial = id->serial_number;
  }
  std::vector<storage::StepRecord> steps;
  steps.reserve(analysis.steps.size());
  for (const plan::Step& step : analysis.steps) steps.push_back(ToStepRecord(step));
  {
    MutexLock lock(impl_->mu);
    if (impl_->shut_down) return FailedPrecondition("the daemon is shutting down; submit later");
  }
  Result<std::int64_t> id = store_->CreateSession(session, steps);
  if (!id.ok()) return id.status().WithContext("storing the new session");
  {
    MutexLock lock(impl_->mu);  // kept as submitted: never parsed back
    impl_->plans.insert_or_assign(*id,
                                  Result<std::shared_ptr<const SessionPlan>>(
                                      std::make_shared<const SessionPlan>(MakeSessionPlan(plan))));
  }
  impl_->Audit(actor, "session.submit", *id,
               "plan \"" + session.name + "\" (" + session.plan_kind + "), " +
                   std::to_string(steps.size()) + " steps, by " + Who(actor));
  if (start_now) return Start(*id, actor);
  return GetSession(*id);
}

Result<v1::Session> SessionManager::Start(SessionId session, const Actor& actor) {
  return impl_->Verb(
      session, actor, "session.start", "started by " + Who(actor),
      [&]() REQUIRES(impl_->mu) -> Status {
        if (impl_->StateLocked(session).ok()) {
          auto kept = impl_->PlanLocked(session, nullptr);
          if (kept.ok() && (*kept)->plan.has_adaptive() && !options_.uncertainty_model) {
            return FailedPrecondition(kNoUncertaintyModel);
          }
        }
        BRDF_ASSIGN_OR_RETURN(
            SessionState to,
            impl_->TransitionLocked(session, SessionEvent::kStart, "started by " + Who(actor)));
        if (to == SessionState::kRunning) impl_->EnsureRunLocked(session);
        return Status::Ok();
      });
}

Result<v1::Session> SessionManager::Pause(SessionId session, PauseMode mode, const Actor& actor,
                                          bool* already_paused) {
  if (already_paused != nullptr) *already_paused = false;
  bool was_paused = false;
  const bool immediate = mode == PauseMode::kImmediate;
  const std::string reason =
      std::string("paused (") + (immediate ? "immediate" : "deferred") + ") by " + Who(actor);
  return impl_->Verb(
      session, actor, "session.pause", reason,
      [&]() REQUIRES(impl_->mu) -> Status {
        Impl& m = *impl_;
        m.mu.AssertHeld();  // the same mutex, under another name
        BRDF_ASSIGN_OR_RETURN(SessionState from, m.StateLocked(session));
        was_paused = from == SessionState::kPaused;
        if (already_paused != nullptr) *already_paused = was_paused;
        if (!immediate) m.live[session].pause_reason = reason;
        BRDF_ASSIGN_OR_RETURN(
            SessionState to,
            m.TransitionLocked(
                session, immediate ? SessionEvent::kPauseImmediate : SessionEvent::kPauseDeferred,
                reason));
        // Paused now (immediate, or while awaiting the operator): stop the run where it is.
        if (to == SessionState::kPaused && m.current && m.current->session() == session) {
          m.current->Cancel(reason);
        }
        return Status::Ok();
      },
      &was_paused);
}

Result<v1::Session> SessionManager::Resume(SessionId session, const Actor& actor) {
  rig_->RetryStageNow();  // a stage that is back need not wait out its reconnect back-off
  return impl_->Verb(session, actor, "session.resume", "resumed by " + Who(actor),
                     [&]() REQUIRES(impl_->mu) -> Status {
                       BRDF_ASSIGN_OR_RETURN(SessionState from, impl_->StateLocked(session));
                       BRDF_ASSIGN_OR_RETURN(SessionState to,
                                             impl_->TransitionLocked(session, SessionEvent::kResume,
                                                                     "resumed by " + Who(actor)));
                       // From pausing, the run is still in its step and simply goes on.
                       if (to == SessionState::kRunning && from != SessionState::kPausing) {
                         impl_->EnsureRunLocked(session);
                       }
                       return Status::Ok();
                     });
}

Result<v1::Session> SessionManager::Abort(SessionId session, const std::string& reason,
                                          const Actor& actor) {
  const std::string why =
      "aborted by " + Who(actor) + (reason.empty() ? std::string() : ": " + reason);
  return impl_->Verb(session, actor, "session.abort", why, [&]() REQUIRES(impl_->mu) -> Status {
    Impl& m = *impl_;
    m.mu.AssertHeld();  // the same mutex, under another name
    BRDF_RETURN_IF_ERROR(m.TransitionLocked(session, SessionEvent::kAbort, why).status());
    if (m.current && m.current->session() == session) m.current->Cancel(why);
    if (m.launch == session) m.launch.reset();
    return Status::Ok();
  });
}

Result<v1::Session> SessionManager::AnswerPrompt(SessionId session, int step_index,
                                                 const std::string& note, const Actor& actor) {
  const std::string detail = "answered the prompt of step " + std::to_string(step_index) + " by " +
                             Who(actor) + (note.empty() ? "" : ": " + note);
  return impl_->Verb(
      session, actor, "session.answer_prompt", detail, [&]() REQUIRES(impl_->mu) -> Status {
        Impl& m = *impl_;
        m.mu.AssertHeld();  // the same mutex, under another name
        BRDF_ASSIGN_OR_RETURN(SessionState state, m.StateLocked(session));
        const std::optional<v1::Prompt>& open = m.live[session].prompt;
        if (state != SessionState::kAwaitingOperator || !open.has_value()) {
          return FailedPrecondition(SessionName(session) + " has no open prompt (it is " +
                                    SessionStateName(state) + "); nothing to answer");
        }
        if (open->step_index() != step_index) {
          return FailedPrecondition(SessionName(session) + ": the open prompt is step " +
                                    std::to_string(open->step_index()) + ", not step " +
                                    std::to_string(step_index) + " (\"" + open->text() +
                                    "\"); answer the open prompt");
        }
        BRDF_RETURN_IF_ERROR(
            m.store.CompleteStep(session, step_index)
                .WithContext("recording the answer to step " + std::to_string(step_index)));
        const v1::Prompt answered = *open;
        BRDF_RETURN_IF_ERROR(m.TransitionLocked(session, SessionEvent::kAnswer, detail).status());
        if (answered.kind() == v1::PROMPT_KIND_RELOCATE_DETECTOR ||
            answered.kind() == v1::PROMPT_KIND_RELOCATE_LAMP_AND_DETECTOR) {
          m.rig.SetManualDelta(answered.pose().delta());
        }
        if (m.current && m.current->session() == session && !m.current->cancelled()) {
          m.current->Answered(step_index);
        } else {
          m.EnsureRunLocked(session);  // no run waits on this prompt: start one at the next step
        }
        return Status::Ok();
      });
}

Result<v1::Session> SessionManager::GetSession(SessionId session) const {
  MutexLock lock(impl_->mu);
  return impl_->BuildLocked(session, /*with_plan=*/true);
}

Result<SessionState> SessionManager::State(SessionId session) const {
  MutexLock lock(impl_->mu);
  return impl_->StateLocked(session);
}

Result<std::vector<v1::Session>> SessionManager::ListSessions(
    const std::vector<SessionState>& states) const {
  BRDF_ASSIGN_OR_RETURN(std::vector<storage::SessionRecord> records, store_->ListSessions());
  std::vector<v1::Session> out;
  MutexLock lock(impl_->mu);
  for (auto it = records.rbegin(); it != records.rend(); ++it) {
    const SessionState state = impl_->live[it->id].state.value_or(it->state);
    if (!states.empty() && std::find(states.begin(), states.end(), state) == states.end()) {
      continue;
    }
    BRDF_ASSIGN_OR_RETURN(v1::Session s, impl_->BuildLocked(it->id, /*with_plan=*/false));
    out.push_back(std::move(s));
  }
  return out;
}

Result<std::shared_ptr<const SessionPlan>> SessionManager::Plan(SessionId session) const {
  MutexLock lock(impl_->mu);
  return impl_->PlanLocked(session, nullptr);
}

v1::RigStatus SessionManager::GetRigStatus() const {
  rig_->RetryStageNow();  // the operator is looking: a stage that is back shows as back
  v1::RigStatus status = ToProto(rig_->GetStatus());
  if (options_.archive_status) {
    *status.mutable_archive() = options_.archive_status();
  } else {
    status.mutable_archive()->set_state(v1::ARCHIVE_STATE_OFF);
  }
  MutexLock lock(impl_->mu);
  if (impl_->holder.has_value()) status.set_active_session_id(std::to_string(*impl_->holder));
  return status;
}

Result<std::shared_ptr<EventSubscription>> SessionManager::Subscribe(SessionId session) {
  Impl& m = *impl_;
  MutexLock lock(m.mu);  // no event can fall between the snapshot and the queue
  BRDF_ASSIGN_OR_RETURN(SessionState state, m.StateLocked(session));
  BRDF_ASSIGN_OR_RETURN(v1::Session snapshot, m.BuildLocked(session, /*with_plan=*/true));
  const std::optional<v1::Prompt> prompt =
      state == SessionState::kAwaitingOperator ? m.live[session].prompt : std::nullopt;
  return m.bus.Subscribe(
      session,
      [&] {
        return EventBus::Opening{snapshot, prompt};
      },
      IsTerminal(state));
}

int SessionManager::AddReadingListener(ReadingListener listener) {
  MutexLock lock(impl_->listeners_mu);
  const int handle = impl_->next_listener++;
  impl_->listeners.emplace(handle, std::move(listener));
  return handle;
}

void SessionManager::RemoveReadingListener(int handle) {
  MutexLock lock(impl_->listeners_mu);
  impl_->listeners.erase(handle);
}

}  // namespace brdf::daemon
