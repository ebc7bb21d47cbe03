#include "core/adaptive/check_seed.h"

#include <string>
#include <vector>

#include "core/adaptive/adaptive_spec.h"
#include "core/adaptive/sample_fixed_design.h"
#include "core/adaptive/seed_design.h"
#include "core/plan/angle_text.h"

namespace brdf::adaptive {

using plan::Deg;
using plan::Num;

void CheckSeedDesign(const v1::Adaptive& adaptive, const plan::RigDescription& rig,
                     plan::ProblemSink& sink) {
  const AdaptiveSpec spec = ResolveAdaptive(adaptive);
  const std::vector<SeedGroup> groups =
      spec.sample_fixed ? std::vector<SeedGroup>{FixedSeedDesign(spec)} : MakeSeedDesign(spec, rig);
  std::vector<std::string> empty;
  std::size_t readings = 0;
  for (const SeedGroup& g : groups) {
    readings += g.poses.size();
    if (g.wanted > 0 && g.poses.size() == static_cast<std::size_t>(g.retro_poses) &&
        !spec.sample_fixed) {
      empty.push_back("δ = " + Deg(g.delta_deg) +
                      (spec.gamma_deg.size() > 1 ? " (γ = " + Deg(g.gamma_deg) + ")" : ""));
    }
  }
  if (spec.sample_fixed &&
      groups.front().poses.size() == static_cast<std::size_t>(groups.front().retro_poses)) {
    sink.Add("adaptive.region",
             "no direction pair in whole degrees lies within this region for the sample-fixed "
             "seed; widen the region's θ limits");
    return;
  }
  if (readings == 0) {
    sink.Add("adaptive.region",
             "no pose within the rig's travel puts both lamp and detector in "
             "this region at any δ of the plan; widen the region's θ limits "
             "or check the rig's travel limits");
    return;
  }
  for (const std::string& where : empty) {
    sink.AddOnce(
        "adaptive.delta",
        "at " + where +
            " no pose within the rig's travel puts both lamp and detector in "
            "the region (θi and θo both within its limits); narrow the δ range or widen the "
            "region");
  }
  if (spec.budget.max_readings > 0 &&
      readings > static_cast<std::size_t>(spec.budget.max_readings)) {
    sink.Add("adaptive.budget.maxReadings",
             std::to_string(spec.budget.max_readings) +
                 " readings is less than the seed design's " + std::to_string(readings) +
                 "; give more, or a smaller seed (seed.retroReadings, seed.readingsPerDelta) or "
                 "fewer detector positions (delta)");
  }
}

void CheckSeedWithinBudget(const v1::Adaptive& adaptive, const plan::PlanSummary& seed,
                           plan::ProblemSink& sink) {
  const Budget budget = ResolveAdaptive(adaptive).budget;
  if (budget.max_rig_s > 0 && seed.estimated_duration_s > budget.max_rig_s) {
    sink.Add("adaptive.budget.maxRigMinutes",
             Num(budget.max_rig_s / 60) + " min is less than the seed design's " +
                 Num(seed.estimated_duration_s / 60) +
                 " min of rig time; give more, or a smaller seed or fewer detector positions");
  }
  if (budget.max_prompts > 0 && seed.operator_interventions > budget.max_prompts) {
    sink.Add("adaptive.budget.maxPrompts",
             std::to_string(budget.max_prompts) + " prompts is less than the seed design's " +
                 std::to_string(seed.operator_interventions) +
                 "; give more, or fewer detector positions (each is a relocation and a "
                 "reference)");
  }
}

}  // namespace brdf::adaptive
