// A chosen round as the steps stored for it (docs/adaptive.md, "Rounds as steps"): its poses
// expanded after the session's stored steps with the plan's policies (plan::ExpandPosesFrom from
// plan::StartAfter), a sample-fixed round first put in prompt order (prompt_order.h), and poses
// cut from the end while the session's steps with the round's would pass the budget.
//
// Why the cut: the chooser charges each pose what it costs by itself (round_cost.h), but the
// steps also carry what the plan's policies add by count or by time (a reference every N readings
// or M minutes, with its prompts); here the budget is checked on the steps themselves, by the
// same summary the stop rule's spend comes from (time scale 1), so a round never passes a budget
// limit. Pure and deterministic.
#pragma once

#include <span>
#include <vector>

#include "brdf/v1/plan.pb.h"
#include "core/adaptive/adaptive_spec.h"
#include "core/adaptive/round_chooser.h"
#include "core/plan/expand_steps.h"
#include "core/plan/rig_description.h"
#include "core/plan/step.h"

namespace brdf::adaptive {

// What `steps` spend, by the timing model for real devices (time scale 1).
Spend SpendOfSteps(std::span<const plan::Step> steps, const v1::Plan& plan,
                   const plan::RigDescription& rig);

// The steps of `round` after `stored` (`start` = plan::StartAfter(stored, ...); `stored_spend` =
// SpendOfSteps(stored, ...), which the caller has for the stop rule), numbered after them.
// `round` is updated to what the steps measure: its poses in measurement order, those cut
// left out (its predicted gain the kept poses' sum, its cost what the steps add, and limited_by
// the budget limit that cut a pose when nothing had before). Empty when no pose fits.
std::vector<plan::Step> RoundSteps(const v1::Plan& plan, const plan::RigDescription& rig,
                                   std::span<const plan::Step> stored, const Spend& stored_spend,
                                   const plan::ExpansionStart& start, const Budget& budget,
                                   Round& round);

}  // namespace brdf::adaptive
