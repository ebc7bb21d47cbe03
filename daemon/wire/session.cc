#include "daemon/wire/session.h"

#include "daemon/wire/enums.h"
#include "daemon/wire/plan.h"
#include "daemon/wire/values.h"

namespace brdf::daemon {
namespace {

// Progress and the current step: the step counts from the record, samples from the steps.
void SetProgress(const SessionFacts& f, SessionState state, v1::Session* s) {
  const storage::SessionRecord& rec = f.record;
  v1::Progress* progress = s->mutable_progress();
  progress->set_done_steps(static_cast<std::uint32_t>(rec.done_steps));
  progress->set_total_steps(static_cast<std::uint32_t>(rec.total_steps));
  int first_pending = -1;
  if (f.steps != nullptr) {
    const storage::StepTally tally = storage::TallySteps(*f.steps);
    first_pending = tally.first_pending;
    progress->set_done_samples(tally.done_samples);
    progress->set_total_samples(tally.samples);
  }
  const bool never_started = state == SessionState::kQueued && !rec.started_at.has_value();
  s->set_current_step(never_started || IsTerminal(state) ? -1 : first_pending);
}

// When it was made, started and finished, and why it is where it is.
void SetTimesAndReasons(const SessionFacts& f, SessionState state, v1::Session* s) {
  const storage::SessionRecord& rec = f.record;
  *s->mutable_created_at() = ToTimestamp(rec.created_at);
  if (rec.started_at.has_value()) *s->mutable_started_at() = ToTimestamp(*rec.started_at);
  if (rec.finished_at.has_value()) *s->mutable_finished_at() = ToTimestamp(*rec.finished_at);
  if (state == SessionState::kAborted || state == SessionState::kFailed) {
    s->set_end_reason(rec.state_reason);
  }
  if (state == SessionState::kQueued || state == SessionState::kPaused ||
      state == SessionState::kPausing || IsTerminal(state)) {
    s->set_state_reason(f.live_state.has_value() && !f.live_reason.empty() ? f.live_reason
                                                                           : rec.state_reason);
  }
}

}  // namespace

v1::Session ToProtoSession(const SessionFacts& f) {
  const storage::SessionRecord& rec = f.record;
  const SessionState state = f.live_state.value_or(rec.state);
  v1::Session s;
  s.set_session_id(std::to_string(rec.id));
  s.set_name(rec.name);
  s.set_state(ToProtoState(state));
  if (f.plan != nullptr) {
    if (f.with_plan) *s.mutable_plan() = f.plan->plan;
    if (f.plan->plan.has_sample()) *s.mutable_sample() = f.plan->plan.sample();
  }
  s.set_uuid(rec.uuid);
  s.set_rig(rec.rig);
  if (rec.grid.has_value()) *s.mutable_grid() = ToProtoGrid(*rec.grid);
  if (f.summary != nullptr) *s.mutable_summary() = ToProtoSummary(*f.summary);
  SetProgress(f, state, &s);
  if (f.eta_s.has_value()) s.set_eta_s(*f.eta_s);
  if (state == SessionState::kAwaitingOperator && f.pending_prompt != nullptr) {
    *s.mutable_pending_prompt() = *f.pending_prompt;
  }
  if (f.last_fault != nullptr) *s.mutable_last_fault() = *f.last_fault;
  s.set_last_quality_code(f.last_quality_code);
  SetTimesAndReasons(f, state, &s);
  return s;
}

v1::SessionStateEvent ToProtoStateEvent(const storage::SessionEventRecord& e) {
  v1::SessionStateEvent out;
  out.set_id(e.id);
  out.set_state(ToProtoState(e.state));
  out.set_reason(e.reason);
  *out.mutable_at() = ToTimestamp(e.at);
  return out;
}

}  // namespace brdf::daemon
