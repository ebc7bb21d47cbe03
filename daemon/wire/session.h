// A session as the API shows it (brdf.v1.Session), from what the stored record says and what its
// server knows beyond it: one set of rules for brdfd (its live state, the plan's summary and ETA,
// the open prompt, the last fault and quality code) and brdf-archive (only what the rig shipped).
// And a session's stored history as the API's SessionStateEvent (ListSessionEvents).
#pragma once

#include <optional>
#include <string>
#include <vector>

#include "brdf/v1/brdf.pb.h"
#include "core/plan/plan_summary.h"
#include "core/session_state.h"
#include "daemon/sessions/session_plan.h"
#include "storage/records.h"

namespace brdf::daemon {

// Everything but the record is optional: what is not given is left out of the message (the ETA,
// the summary, the prompt, the fault) or shown as unknown (last_quality_code −1).
struct SessionFacts {
  explicit SessionFacts(const storage::SessionRecord& r) : record(r) {}

  const storage::SessionRecord& record;
  // The state when the server knows a newer one than the record holds, and why it is in it
  // (empty: the record's reason).
  std::optional<SessionState> live_state;
  std::string live_reason;
  // The plan, parsed; null when it does not parse (then shown as none). Session.plan only with
  // `with_plan` (ListSessions leaves it out); the sample always.
  const SessionPlan* plan = nullptr;
  bool with_plan = false;
  // The steps: progress in samples and the current step. Without them only the step counts.
  const std::vector<storage::StepRecord>* steps = nullptr;
  const plan::PlanSummary* summary = nullptr;
  std::optional<double> eta_s;
  const v1::Prompt* pending_prompt = nullptr;  // shown while awaiting the operator
  const v1::Fault* last_fault = nullptr;
  int last_quality_code = -1;
};

v1::Session ToProtoSession(const SessionFacts& facts);

v1::SessionStateEvent ToProtoStateEvent(const storage::SessionEventRecord& event);

}  // namespace brdf::daemon
