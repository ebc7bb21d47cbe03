// How an adaptive plan's estimate states its bounds, for people (brdfctl validate): the target
// and, from the budget, at most so many readings, so much rig time, so many prompts; a limit left
// unset is said to be bounded only through the others. The seed design's own cost is the plan's
// summary (ValidatePlan), printed beside it.
#pragma once

#include <string>

#include "brdf/v1/plan.pb.h"

namespace brdf::adaptive {

// "then rounds until U (k = 2) ≤ 5 % over the region, or at most 464 readings, 40 min of rig
// time, 60 prompts (seed included)".
std::string AdaptiveBoundsText(const v1::Adaptive& adaptive);

}  // namespace brdf::adaptive
