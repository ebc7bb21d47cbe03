// core/plan's results in the API's messages (proto/brdf/v1/brdf.proto), so that the daemon's
// services stay thin.
#pragma once

#include <span>

#include "brdf/v1/brdf.pb.h"
#include "core/plan/analyze_plan.h"

namespace brdf::plan {

v1::PlanSummary ToProto(const PlanSummary& summary);
v1::PlanProblem ToProto(const Problem& problem);
v1::Pose ToProto(const Pose& pose);
v1::Directions ToProto(const Directions& directions);

// The ValidatePlan RPC's answer: valid, every problem, and the summary (zeros when invalid).
v1::ValidatePlanResponse ToValidatePlanResponse(const PlanAnalysis& analysis);

// A prompt step as the API's Prompt (raised_at left unset for the caller to fill).
v1::Prompt ToPrompt(const Step& step);

}  // namespace brdf::plan
