// The checks of an adaptive plan that need its seed design (seed_design.h): every detector
// position reaches the region, and the seed fits the budget. Part of ValidatePlan
// (core/plan/analyze_plan.h); the field checks come first (core/plan/check_fields.h).
#pragma once

#include "brdf/v1/plan.pb.h"
#include "core/plan/plan_summary.h"
#include "core/plan/problem.h"
#include "core/plan/rig_description.h"

namespace brdf::adaptive {

// Precondition: the adaptive fields passed CheckPlanFields' own checks. Adds a problem for each
// (γ, δ) at which no pose within the rig's travel puts both directions in the region (path
// "adaptive.delta", or "adaptive.region" when no δ reaches it; in the sample-fixed form,
// "adaptive.region" when no whole-degree direction pair lies in it), and one when the seed alone
// has more readings than budget.maxReadings.
void CheckSeedDesign(const v1::Adaptive& adaptive, const plan::RigDescription& rig,
                     plan::ProblemSink& sink);

// After expansion: a problem when the seed's own steps (`seed`, their summary) need more rig
// time or prompts than the budget allows.
void CheckSeedWithinBudget(const v1::Adaptive& adaptive, const plan::PlanSummary& seed,
                           plan::ProblemSink& sink);

}  // namespace brdf::adaptive
