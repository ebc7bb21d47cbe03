// How an adaptive plan's estimate states its bounds, for people (brdfctl validate): the target
// and, from the budget, at most so many readings, so much rig time, so many prompts; a limit left
// unset is said to be bounded only through the others. The seed design's own cost is the plan's
// summary (ValidatePlan), printed beside it.
#pragma once

#include <string>

#include "brdf/v1/plan.pb.h"

namespace brdf::adaptive {

// "then rounds of up to 24 readings until the expanded uncertainty (k = 2) is at most 5 % over the
// region, or at most 464 readings, 38 min of rig time (prompts included) and 60 prompts in all
// (seed included)".
std::string AdaptiveBoundsText(const v1::Adaptive& adaptive);

// The same for a whole plan; in the sample-fixed form (Adaptive.sample_fixed) followed by what
// every pose costs in prompts under the plan's policies: "; sample-fixed: each pose is 3 prompts
// (lamp and detector set by hand, then a reference's white and sample mounting)".
std::string AdaptiveBoundsText(const v1::Plan& plan);

}  // namespace brdf::adaptive
