// Helpers shared by the plan tests: a plan from JSON text (the way operators write them) and
// step filters.
#pragma once

#include <gtest/gtest.h>

#include <string>
#include <vector>

#include "core/plan/analyze_plan.h"
#include "core/plan/plan_json.h"

namespace brdf::plan::testing {

inline v1::Plan PlanFromJson(const std::string& json) {
  Result<v1::Plan> plan = ParsePlanJson(json);
  EXPECT_TRUE(plan.ok()) << plan.status().ToString();
  return plan.ok() ? *plan : v1::Plan();
}

inline std::vector<Step> Expand(const v1::Plan& plan, const RigDescription& rig = {}) {
  Result<std::vector<Step>> steps = ExpandPlan(plan, rig);
  EXPECT_TRUE(steps.ok()) << steps.status().ToString();
  return steps.ok() ? *steps : std::vector<Step>();
}

inline std::vector<Step> OfKind(const std::vector<Step>& steps, StepKind kind) {
  std::vector<Step> out;
  for (const Step& s : steps) {
    if (s.kind == kind) out.push_back(s);
  }
  return out;
}

inline std::vector<Step> Prompts(const std::vector<Step>& steps, PromptKind kind) {
  std::vector<Step> out;
  for (const Step& s : steps) {
    if (s.kind == v1::STEP_KIND_PROMPT && s.prompt == kind) out.push_back(s);
  }
  return out;
}

// A step of `kind` at pose 0 (a reading or a prompt), and a move of α and β to (alpha, beta).
inline Step StepOfKind(StepKind kind) {
  Step s;
  s.kind = kind;
  return s;
}
inline Step MoveTo(double alpha, double beta) {
  Step s = StepOfKind(v1::STEP_KIND_MOVE);
  s.pose.alpha = alpha;
  s.pose.beta = beta;
  return s;
}

}  // namespace brdf::plan::testing
