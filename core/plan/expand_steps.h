// The expansion of a checked plan into steps (the work behind ExpandPlan, see
// core/plan/analyze_plan.h for the public entry points and the full order of steps).
//
// Precondition: CheckPlanFields found no problem (every number finite and in range, counts
// bounded). The problems only the expansion can see are added to `sink`: poses of the grid
// beyond the β (or γ) travel, reference poses beyond the α/β travel or too close to grazing.
// Stops adding steps after kMaxSteps + 1; the caller reports the overflow.
#pragma once

#include <vector>

#include "brdf/v1/plan.pb.h"
#include "core/plan/problem.h"
#include "core/plan/rig_description.h"
#include "core/plan/step.h"

namespace brdf::plan {

std::vector<Step> ExpandCheckedPlan(const v1::Plan& plan, const RigDescription& rig,
                                    ProblemSink& sink);

}  // namespace brdf::plan
