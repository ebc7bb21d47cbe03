#include "core/adaptive/stop_rule.h"

namespace brdf::adaptive {

const char* StopReasonText(StopReason reason) {
  switch (reason) {
    case StopReason::kContinue:
      return "continue";
    case StopReason::kTargetReached:
      return "target reached";
    case StopReason::kReadingBudget:
      return "reading budget spent";
    case StopReason::kTimeBudget:
      return "rig-time budget spent";
    case StopReason::kPromptBudget:
      return "prompt budget spent";
    case StopReason::kNothingToGain:
      return "no pose within the budget is predicted to lower the uncertainty";
  }
  return "?";
}

StopReason ShouldStop(double remaining, const Target& target, const Budget& budget,
                      const Spend& spent) {
  if (remaining <= target.level) return StopReason::kTargetReached;
  if (budget.max_readings > 0 && spent.readings >= budget.max_readings) {
    return StopReason::kReadingBudget;
  }
  if (budget.max_rig_s > 0 && spent.seconds >= budget.max_rig_s) return StopReason::kTimeBudget;
  if (budget.max_prompts > 0 && spent.prompts >= budget.max_prompts) {
    return StopReason::kPromptBudget;
  }
  return StopReason::kContinue;
}

StopReason AfterChoosing(const Round& round) {
  if (!round.poses.empty()) return StopReason::kContinue;
  return round.limited_by != StopReason::kContinue ? round.limited_by : StopReason::kNothingToGain;
}

}  // namespace brdf::adaptive
