#include "core/adaptive/budget_text.h"

#include <vector>

#include "core/adaptive/adaptive_spec.h"
#include "core/adaptive/sample_fixed_design.h"
#include "core/plan/angle_text.h"

namespace brdf::adaptive {

std::string AdaptiveBoundsText(const v1::Adaptive& adaptive) {
  const AdaptiveSpec spec = ResolveAdaptive(adaptive);
  const std::string quantity = spec.target.kind == TargetKind::kExpandedUncertainty
                                   ? "the expanded uncertainty (k = 2)"
                                   : "the expected error";
  std::vector<std::string> limits;
  if (spec.budget.max_readings > 0) {
    limits.push_back(std::to_string(spec.budget.max_readings) + " readings");
  }
  if (spec.budget.max_rig_s > 0) {
    limits.push_back(plan::Num(spec.budget.max_rig_s / 60) + " min of rig time (prompts included)");
  }
  if (spec.budget.max_prompts > 0) {
    limits.push_back(std::to_string(spec.budget.max_prompts) + " prompts");
  }
  std::string text = "then rounds of up to " + std::to_string(spec.round_readings) +
                     " readings until " + quantity + " is at most " +
                     plan::Num(spec.target.level * 100) + " % over the region, or at most ";
  for (std::size_t i = 0; i < limits.size(); ++i) {
    if (i > 0) text += i + 1 == limits.size() ? " and " : ", ";
    text += limits[i];
  }
  text += " in all (seed included)";
  if (limits.size() < 3) text += "; what the budget leaves unset is bounded only by the rest";
  return text;
}

std::string AdaptiveBoundsText(const v1::Plan& plan) {
  std::string text = AdaptiveBoundsText(plan.adaptive());
  if (!plan.adaptive().has_sample_fixed()) return text;
  // Prompts do not depend on the rig's devices (the default rig's timing is not used here).
  const int prompts = FixedPoseCost(plan, plan::RigDescription{}).prompts;
  text += "; sample-fixed: each pose is " + std::to_string(prompts) +
          (prompts == 1 ? " prompt (lamp and detector set by hand)"
                        : " prompts (lamp and detector set by hand, then a reference's mounting)");
  return text;
}

}  // namespace brdf::adaptive
