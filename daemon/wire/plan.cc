#include "daemon/wire/plan.h"

#include "daemon/wire/enums.h"
#include "daemon/wire/values.h"

namespace brdf::daemon {

v1::PlanSummary ToProtoSummary(const plan::PlanSummary& s) {
  v1::PlanSummary p;
  p.set_step_count(static_cast<std::uint32_t>(s.step_count));
  p.set_sample_readings(static_cast<std::uint32_t>(s.sample_readings));
  p.set_reference_readings(static_cast<std::uint32_t>(s.reference_readings));
  p.set_dark_readings(static_cast<std::uint32_t>(s.dark_readings));
  p.set_operator_interventions(static_cast<std::uint32_t>(s.operator_interventions));
  p.set_estimated_duration_s(s.estimated_duration_s);
  p.set_physical_lower_bound_s(s.physical_lower_bound_s);
  return p;
}

v1::PlanProblem ToProtoProblem(const plan::Problem& problem) {
  v1::PlanProblem p;
  p.set_field_path(problem.field_path);
  p.set_message(problem.message);
  return p;
}

v1::ValidatePlanResponse ToValidatePlanResponse(const plan::PlanAnalysis& analysis) {
  v1::ValidatePlanResponse r;
  r.set_valid(analysis.valid());
  for (const plan::Problem& problem : analysis.problems)
    *r.add_problems() = ToProtoProblem(problem);
  const plan::PlanSummary& s = analysis.summary;
  r.set_step_count(static_cast<std::uint32_t>(s.step_count));
  r.set_operator_interventions(static_cast<std::uint32_t>(s.operator_interventions));
  r.set_estimated_duration_s(s.estimated_duration_s);
  r.set_physical_lower_bound_s(s.physical_lower_bound_s);
  *r.mutable_summary() = ToProtoSummary(s);
  return r;
}

storage::StepRecord ToStepRecord(const plan::Step& step) {
  storage::StepRecord r;
  r.step_index = step.index;
  r.kind = ToStorageKind(step.kind);
  r.pose = step.pose;
  if (step.kind == v1::STEP_KIND_PROMPT) {
    r.prompt = step.prompt_text;
    r.prompt_kind = PromptKindWord(step.prompt);
    r.expected_action = step.expected_action;
  }
  r.target = step.target;
  r.label = step.label;
  return r;
}

plan::Step ToPlanStep(const storage::StepRecord& record) {
  plan::Step s;
  s.index = record.step_index;
  s.kind = ToProtoKind(record.kind);
  s.pose = record.pose;
  if (record.prompt_kind.has_value()) s.prompt = ParsePromptKindWord(*record.prompt_kind);
  s.prompt_text = record.prompt.value_or("");
  s.expected_action = record.expected_action.value_or("");
  s.label = record.label;
  s.target = record.target;
  return s;
}

std::vector<plan::Step> ToPlanSteps(const std::vector<storage::StepRecord>& records) {
  std::vector<plan::Step> steps;
  steps.reserve(records.size());
  for (const auto& r : records) steps.push_back(ToPlanStep(r));
  return steps;
}

v1::Prompt ToPrompt(const storage::StepRecord& step) {
  v1::Prompt p;
  p.set_step_index(step.step_index);
  p.set_kind(step.prompt_kind.has_value() ? ParsePromptKindWord(*step.prompt_kind)
                                          : v1::PROMPT_KIND_UNSPECIFIED);
  p.set_text(step.prompt.value_or(step.label));
  p.set_expected_action(step.expected_action.value_or(""));
  *p.mutable_pose() = ToProtoPose(step.pose);
  if (step.target.has_value()) *p.mutable_target() = ToProtoDirections(*step.target);
  return p;
}

}  // namespace brdf::daemon
