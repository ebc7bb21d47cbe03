#include "daemon/sessions/session_plan.h"

#include <string>
#include <utility>

#include "core/plan/plan_json.h"

namespace brdf::daemon {

SessionPlan MakeSessionPlan(v1::Plan plan) {
  SessionPlan out;
  out.settings = plan::ResolveSettings(plan);
  out.plan = std::move(plan);
  return out;
}

Result<SessionPlan> ParseSessionPlan(const storage::SessionRecord& record) {
  Result<v1::Plan> plan = plan::ParsePlanJson(record.plan_json);
  if (!plan.ok()) {
    return Internal("session " + std::to_string(record.id) +
                    ": its stored plan does not parse: " + plan.status().message());
  }
  return MakeSessionPlan(std::move(*plan));
}

}  // namespace brdf::daemon
