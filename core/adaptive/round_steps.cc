#include "core/adaptive/round_steps.h"

#include "core/adaptive/prompt_order.h"
#include "core/plan/plan_settings.h"
#include "core/plan/plan_summary.h"

namespace brdf::adaptive {

Spend SpendOfSteps(std::span<const plan::Step> steps, const v1::Plan& plan,
                   const plan::RigDescription& rig) {
  plan::RigDescription real = rig;
  real.time_scale = 1;
  const plan::PlanSummary s =
      plan::SummarizeSteps(steps, real, plan::ResolveSettings(plan).measurement);
  return {s.sample_readings, s.estimated_duration_s, s.operator_interventions};
}

std::vector<plan::Step> RoundSteps(const v1::Plan& plan, const plan::RigDescription& rig,
                                   std::span<const plan::Step> stored, const Spend& stored_spend,
                                   const plan::ExpansionStart& start, const Budget& budget,
                                   Round& round) {
  if (plan::SampleFixedMethod(plan)) OrderRoundForPrompts(round, start.model);
  std::vector<plan::Step> all(stored.begin(), stored.end());
  while (!round.poses.empty()) {
    std::vector<Pose> poses;
    for (const ChosenPose& c : round.poses) poses.push_back(c.pose);
    std::vector<plan::Step> added =
        plan::ExpandPosesFrom(plan, rig, start, poses, static_cast<int>(stored.size()));
    all.resize(stored.size());
    all.insert(all.end(), added.begin(), added.end());
    const Spend with = SpendOfSteps(all, plan, rig);
    const PoseCost total{with.seconds, with.prompts};
    const StopReason limit = LimitPassed(budget, Spend{}, total, with.readings);
    if (limit == StopReason::kContinue) {
      round.cost = {with.seconds - stored_spend.seconds, with.prompts - stored_spend.prompts};
      return added;
    }
    if (round.limited_by == StopReason::kContinue) round.limited_by = limit;
    round.poses.pop_back();
    round.predicted_gain = 0;
    for (const ChosenPose& c : round.poses) round.predicted_gain += c.predicted_gain;
  }
  round.cost = {};
  return {};
}

}  // namespace brdf::adaptive
