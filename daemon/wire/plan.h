// Plans and steps between core/plan, storage and the API: a plan's summary and problems as the
// API shows them (ValidatePlan, Session.summary), a session's expanded steps as storage keeps them
// and back (the executor works from stored steps; the timing model from plan steps), and a stored
// prompt step as the API's Prompt.
#pragma once

#include <vector>

#include "brdf/v1/brdf.pb.h"
#include "core/plan/analyze_plan.h"
#include "core/plan/plan_summary.h"
#include "core/plan/problem.h"
#include "core/plan/step.h"
#include "storage/records.h"

namespace brdf::daemon {

v1::PlanSummary ToProtoSummary(const plan::PlanSummary& summary);
v1::PlanProblem ToProtoProblem(const plan::Problem& problem);

// The ValidatePlan RPC's answer: valid, every problem, and the summary (zeros when invalid).
v1::ValidatePlanResponse ToValidatePlanResponse(const plan::PlanAnalysis& analysis);

// An expanded step as storage keeps it, and back (for the timing model).
storage::StepRecord ToStepRecord(const plan::Step& step);
plan::Step ToPlanStep(const storage::StepRecord& record);
std::vector<plan::Step> ToPlanSteps(const std::vector<storage::StepRecord>& records);

// A stored prompt step as the API's Prompt (raised_at left unset).
v1::Prompt ToPrompt(const storage::StepRecord& step);

}  // namespace brdf::daemon
