#include "core/plan/analyze_plan.h"

#include <string>
#include <utility>

#include "core/adaptive/check_seed.h"
#include "core/plan/check_fields.h"
#include "core/plan/expand_steps.h"
#include "core/plan/plan_settings.h"

namespace brdf::plan {

PlanAnalysis AnalyzePlan(const v1::Plan& plan, const RigDescription& rig, double time_scale) {
  PlanAnalysis out;
  ProblemSink sink;
  CheckPlanFields(plan, rig, sink);
  if (!sink.empty()) {
    out.problems = sink.Take();
    return out;
  }
  std::vector<Step> steps = ExpandCheckedPlan(plan, rig, sink);
  if (steps.empty() && sink.empty()) {
    // Each method reports why it found nothing to do; this guards a method that does not.
    sink.Add("", "the plan expands to no steps; give at least one pose or target to measure");
  }
  if (steps.size() > static_cast<std::size_t>(kMaxSteps)) {
    sink.Add("", "the plan expands to more than " + std::to_string(kMaxSteps) +
                     " steps (the cap); use coarser steps, fewer targets, or split the plan");
  }
  out.problems = sink.Take();
  if (!out.problems.empty()) return out;
  RigDescription timed = rig;
  timed.time_scale = time_scale;
  out.summary = SummarizeSteps(steps, timed, ResolveSettings(plan).measurement);
  if (plan.has_adaptive()) {
    // A budget's rig time is a real rig's (time scale 1), whatever a simulated rig runs at.
    RigDescription real_rig = rig;
    real_rig.time_scale = 1;
    const PlanSummary real = SummarizeSteps(steps, real_rig, ResolveSettings(plan).measurement);
    adaptive::CheckSeedWithinBudget(plan.adaptive(), real, sink);
    out.problems = sink.Take();
    if (!out.problems.empty()) {
      out.summary = {};
      return out;
    }
  }
  out.steps = std::move(steps);
  return out;
}

std::vector<Problem> ValidatePlan(const v1::Plan& plan, const RigDescription& rig) {
  return AnalyzePlan(plan, rig).problems;
}

Result<std::vector<Step>> ExpandPlan(const v1::Plan& plan, const RigDescription& rig) {
  PlanAnalysis a = AnalyzePlan(plan, rig);
  if (!a.valid()) {
    return InvalidArgument("plan \"" + plan.name() + "\" is not valid for this rig (" +
                           std::to_string(a.problems.size()) + " problem" +
                           (a.problems.size() == 1 ? "" : "s") + "); fix:\n" +
                           FormatProblems(a.problems));
  }
  return std::move(a.steps);
}

}  // namespace brdf::plan
