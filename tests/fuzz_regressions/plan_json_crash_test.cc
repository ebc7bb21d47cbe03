// Crashes the plan_json fuzzer found, each with its minimal input and the behaviour the plan
// checker documents for it.
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <string>

#include "core/plan/analyze_plan.h"
#include "core/plan/plan_json.h"

namespace brdf::plan {
namespace {

using ::testing::HasSubstr;

// CI fuzz smoke, 2026-12-03: α = 0 only and δ from 90° up put the detector at grazing or below
// at every β, so the grid had no pose; AnalyzePlan called the plan valid with zero steps (a
// session that would record nothing). It must be refused, naming the grid and what to change.
TEST(PlanJsonCrashTest, SampleRotationGridWithNoValidPoseIsRefused) {
  const Result<v1::Plan> plan = ParsePlanJson(
      R"({"sampleRotation":{"alpha":{"start":0,"stop":10,"step":11},"beta":{"step":90},)"
      R"("delta":{"start":90}}})");
  ASSERT_TRUE(plan.ok()) << plan.status().ToString();
  RigDescription motorized;
  motorized.has_gamma_axis = true;
  motorized.has_detector_arm = true;
  for (const RigDescription& rig : {RigDescription{}, motorized}) {
    const PlanAnalysis a = AnalyzePlan(*plan, rig);
    EXPECT_FALSE(a.valid());
    EXPECT_TRUE(a.steps.empty());
    ASSERT_EQ(a.problems.size(), 1u) << FormatProblems(a.problems);
    EXPECT_EQ(a.problems[0].field_path, "sampleRotation");
    EXPECT_THAT(a.problems[0].message, HasSubstr("no pose of the grid"));
    EXPECT_THAT(a.problems[0].message, HasSubstr("δ in [90°, 150°]"));
    EXPECT_THAT(a.problems[0].message, HasSubstr("lower δ"));
    EXPECT_FALSE(ExpandPlan(*plan, rig).ok());
  }
  // The same grid with δ starting lower has poses: the refusal is about the empty grid only.
  const Result<v1::Plan> lower = ParsePlanJson(
      R"({"sampleRotation":{"alpha":{"start":0,"stop":10,"step":11},"beta":{"step":90},)"
      R"("delta":{"start":30}}})");
  ASSERT_TRUE(lower.ok());
  EXPECT_TRUE(AnalyzePlan(*lower, RigDescription{}).valid());
}

}  // namespace
}  // namespace brdf::plan
