#include "core/plan/plan_proto.h"

namespace brdf::plan {

v1::PlanSummary ToProto(const PlanSummary& s) {
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

v1::PlanProblem ToProto(const Problem& problem) {
  v1::PlanProblem p;
  p.set_field_path(problem.field_path);
  p.set_message(problem.message);
  return p;
}

v1::Pose ToProto(const Pose& pose) {
  v1::Pose p;
  p.set_alpha(pose.alpha);
  p.set_beta(pose.beta);
  p.set_gamma(pose.gamma);
  p.set_delta(pose.delta);
  return p;
}

v1::Directions ToProto(const Directions& d) {
  v1::Directions p;
  p.set_theta_i(d.theta_i);
  p.set_phi_i(d.phi_i);
  p.set_theta_o(d.theta_o);
  p.set_phi_o(d.phi_o);
  return p;
}

v1::ValidatePlanResponse ToValidatePlanResponse(const PlanAnalysis& analysis) {
  v1::ValidatePlanResponse r;
  r.set_valid(analysis.valid());
  for (const Problem& problem : analysis.problems) *r.add_problems() = ToProto(problem);
  const PlanSummary& s = analysis.summary;
  r.set_step_count(static_cast<std::uint32_t>(s.step_count));
  r.set_operator_interventions(static_cast<std::uint32_t>(s.operator_interventions));
  r.set_estimated_duration_s(s.estimated_duration_s);
  r.set_physical_lower_bound_s(s.physical_lower_bound_s);
  *r.mutable_summary() = ToProto(s);
  return r;
}

v1::Prompt ToPrompt(const Step& step) {
  v1::Prompt p;
  p.set_step_index(step.index);
  p.set_kind(step.prompt);
  p.set_text(step.prompt_text);
  p.set_expected_action(step.expected_action);
  *p.mutable_pose() = ToProto(step.pose);
  if (step.target.has_value()) *p.mutable_target() = ToProto(*step.target);
  return p;
}

}  // namespace brdf::plan
