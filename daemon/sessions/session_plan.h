// A session's plan as the daemon keeps it: parsed ONCE from the stored JSON, when the session is
// submitted (the plan given) or first loaded, and kept with the session (SessionManager::Plan).
// Every user (the executor's settings, GetSession's plan and estimates, the index cache's
// isotropic/anisotropic choice, StreamReadings' averaging) reads this instead of parsing again.
//
// A stored plan that no longer parses (a database edited by hand, a plan from a newer brdfd) is
// reported one way: ParseSessionPlan's kInternal "session N: its stored plan does not parse:
// <why>", logged once by the SessionManager when it loads the session. Whoever cannot work
// without the plan returns that Status (the executor stops, and the session fails with it as
// the reason: measuring without the plan's settings is unsafe; the index cache answers it);
// whoever only shows the session (GetSession, StreamReadings) shows it without the plan.
#pragma once

#include <cstdint>

#include "brdf/v1/brdf.pb.h"
#include "core/plan/plan_settings.h"
#include "core/status.h"
#include "storage/records.h"

namespace brdf::daemon {

struct SessionPlan {
  v1::Plan plan;
  plan::PlanSettings settings;  // plan::ResolveSettings(plan): every unset policy defaulted
};

// The plan as submitted (no parse).
SessionPlan MakeSessionPlan(v1::Plan plan);

// The record's stored plan, parsed. kInternal as above when it does not parse.
Result<SessionPlan> ParseSessionPlan(const storage::SessionRecord& record);

}  // namespace brdf::daemon
