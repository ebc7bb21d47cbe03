// Helpers shared by the plan tests: a plan from JSON text (the way operators write them) and
// step filters.
#pragma once

#include <gtest/gtest.h>

#include <cstdio>
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

// The problem with field path `path`, or nullptr.
inline const Problem* FindProblem(const std::vector<Problem>& problems, const std::string& path) {
  for (const Problem& p : problems) {
    if (p.field_path == path) return &p;
  }
  return nullptr;
}

#ifdef BRDF_EXAMPLES_DIR
// The text of examples/plans/`name` ("" when it cannot be read, with a failure).
inline std::string ReadExamplePlan(const std::string& name) {
  std::FILE* f = std::fopen((std::string(BRDF_EXAMPLES_DIR) + "/" + name).c_str(), "rb");
  EXPECT_NE(f, nullptr) << name;
  std::string text;
  if (f == nullptr) return text;
  char buf[4096];
  for (std::size_t n; (n = std::fread(buf, 1, sizeof buf, f)) > 0;) text.append(buf, n);
  std::fclose(f);
  return text;
}
#endif

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
