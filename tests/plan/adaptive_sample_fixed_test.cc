// The sample-fixed method's form of an adaptive plan (Adaptive.sampleFixed): validation with
// field paths, the seed as relocation prompts (no moves, the angles to set in each prompt, the
// references as in fixed sample-fixed plans), the estimate's prompts, and the example plan.
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <string>
#include <vector>

#include "core/geometry.h"
#include "core/plan/analyze_plan.h"
#include "core/plan/angle_text.h"
#include "core/plan/plan_json.h"
#include "plan_test_util.h"

namespace brdf::plan {
namespace {

using testing::FindProblem;
using ::testing::HasSubstr;
using testing::OfKind;
using testing::PlanFromJson;
using testing::Prompts;
using testing::ReadExamplePlan;

// An adaptive sample-fixed plan with `fields` added to "adaptive" and `policies` to the plan.
std::string Fixed(const std::string& fields, const std::string& policies = "") {
  return R"({"name": "f", "adaptive": {"target": {"expandedUncertainty": 0.05},
    "budget": {"maxPrompts": 200}, "sampleFixed": {})" +
         fields + "}" + policies + "}";
}

TEST(AdaptiveSampleFixedTest, ExampleIsValidAndItsSeedIsAPromptPerPose) {
  const PlanAnalysis a =
      AnalyzePlan(PlanFromJson(ReadExamplePlan("adaptive-sample-fixed.json")), RigDescription{});
  ASSERT_TRUE(a.valid()) << FormatProblems(a.problems);
  // 6 retro-reflection poses and 24 space-filling ones.
  EXPECT_EQ(a.summary.sample_readings, 30);
  EXPECT_TRUE(OfKind(a.steps, v1::STEP_KIND_MOVE).empty());  // the sample never moves
  const std::vector<Step> relocations =
      Prompts(a.steps, v1::PROMPT_KIND_RELOCATE_LAMP_AND_DETECTOR);
  EXPECT_EQ(relocations.size(), 30u);
  EXPECT_TRUE(Prompts(a.steps, v1::PROMPT_KIND_RELOCATE_DETECTOR).empty());
  // References by time (every 15 min): each a white and a sample mounting prompt; the estimate
  // counts every prompt.
  const int references = static_cast<int>(OfKind(a.steps, v1::STEP_KIND_REFERENCE).size());
  EXPECT_GE(references, 2);
  EXPECT_EQ(a.summary.operator_interventions, 30 + 2 * references);
  // Rig time: at least the operator's 30 s per prompt.
  EXPECT_GE(a.summary.estimated_duration_s, 30.0 * a.summary.operator_interventions);
}

TEST(AdaptiveSampleFixedTest, EachPromptSaysWhatToSetAndTheReadingKeepsTheTarget) {
  const std::vector<Step> steps = testing::Expand(PlanFromJson(Fixed(R"(,
    "region": {"thetaIMinDeg": 10, "thetaIMaxDeg": 60, "thetaOMaxDeg": 70},
    "seed": {"retroReadings": 3})")));
  const std::vector<Step> samples = OfKind(steps, v1::STEP_KIND_SAMPLE);
  ASSERT_EQ(samples.size(), 3u + 12u);
  EXPECT_THAT(samples.front().label, HasSubstr("retro-reflection"));
  int relocation = 0;
  for (std::size_t i = 0; i < steps.size(); ++i) {
    if (steps[i].prompt != v1::PROMPT_KIND_RELOCATE_LAMP_AND_DETECTOR) continue;
    ++relocation;
    const Step& prompt = steps[i];
    ASSERT_TRUE(prompt.target.has_value());
    const IsoDirection d = ToIsotropic(*prompt.target);
    EXPECT_THAT(prompt.prompt_text, HasSubstr("θi = " + Deg(d.theta_i)));
    EXPECT_THAT(prompt.prompt_text, HasSubstr("θo = " + Deg(d.theta_o)));
    EXPECT_THAT(prompt.prompt_text, HasSubstr("relative azimuth φ = " + Deg(d.phi)));
    EXPECT_THAT(prompt.prompt_text, HasSubstr("of 15"));
    // Whole degrees (set by hand), within the region.
    EXPECT_EQ(d.theta_i, std::round(d.theta_i));
    EXPECT_EQ(d.theta_o, std::round(d.theta_o));
    EXPECT_EQ(d.phi, std::round(d.phi));
    EXPECT_GE(d.theta_i, 10);
    EXPECT_LE(d.theta_i, 60);
    EXPECT_LE(d.theta_o, 70);
    // The sample reading after it (after a reference block when one is due) keeps the target,
    // and its pose is the equivalent pose.
    std::size_t j = i + 1;
    while (j < steps.size() && steps[j].kind != v1::STEP_KIND_SAMPLE) ++j;
    ASSERT_LT(j, steps.size());
    EXPECT_EQ(steps[j].target, prompt.target);
    const IsoDirection via_pose = ToIsotropic(PoseToDirections(steps[j].pose));
    EXPECT_NEAR(via_pose.theta_i, d.theta_i, 1e-6);
    EXPECT_NEAR(via_pose.theta_o, d.theta_o, 1e-6);
    EXPECT_NEAR(via_pose.phi, d.phi, 1e-6);
  }
  EXPECT_EQ(relocation, 15);
}

TEST(AdaptiveSampleFixedTest, ReferencePerPositionIsAReferenceAtEveryTarget) {
  // The default reference policy (perDetectorPosition) makes each relocation a reference, as in a
  // fixed sample-fixed plan: three prompts per pose.
  const PlanAnalysis a =
      AnalyzePlan(PlanFromJson(Fixed(R"(, "seed": {"retroReadings": 2})")), RigDescription{});
  ASSERT_TRUE(a.valid()) << FormatProblems(a.problems);
  EXPECT_EQ(a.summary.sample_readings, 14);
  EXPECT_EQ(a.summary.reference_readings, 14);
  EXPECT_EQ(a.summary.operator_interventions, 3 * 14);
}

TEST(AdaptiveSampleFixedTest, SeedIsDeterministic) {
  const v1::Plan plan = PlanFromJson(Fixed(R"(, "seed": {"retroReadings": 4})"));
  const std::vector<Step> a = testing::Expand(plan);
  const std::vector<Step> b = testing::Expand(plan);
  ASSERT_EQ(a.size(), b.size());
  for (std::size_t i = 0; i < a.size(); ++i) {
    EXPECT_EQ(a[i].pose, b[i].pose);
    EXPECT_EQ(a[i].prompt_text, b[i].prompt_text);
  }
}

TEST(AdaptiveSampleFixedTest, FieldsOfTheRotationRigAreRefusedWithTheirPaths) {
  const v1::Plan plan = PlanFromJson(R"({"name": "f", "anisotropic": true, "adaptive": {
    "target": {"expandedUncertainty": 0.05}, "budget": {"maxPrompts": 200},
    "delta": {"step": 22.5}, "gamma": [0, 90], "seed": {"readingsPerDelta": 6, "deltaEvery": 4},
    "sampleFixed": {"seedReadings": 501}}})");
  const std::vector<Problem> problems = ValidatePlan(plan, RigDescription{});
  for (const char* path :
       {"adaptive.delta", "adaptive.gamma", "adaptive.seed.readingsPerDelta",
        "adaptive.seed.deltaEvery", "adaptive.sampleFixed", "adaptive.sampleFixed.seedReadings"}) {
    EXPECT_NE(FindProblem(problems, path), nullptr) << path << "\n" << FormatProblems(problems);
  }
  EXPECT_THAT(FindProblem(problems, "adaptive.delta")->message, HasSubstr("sample-fixed"));
  EXPECT_THAT(FindProblem(problems, "adaptive.seed.readingsPerDelta")->message,
              HasSubstr("sampleFixed.seedReadings"));
  EXPECT_THAT(FindProblem(problems, "adaptive.sampleFixed")->message, HasSubstr("isotropic"));
  EXPECT_THAT(FindProblem(problems, "adaptive.sampleFixed.seedReadings")->message,
              HasSubstr("1 … 500"));
}

TEST(AdaptiveSampleFixedTest, SharedFieldsAreStillChecked) {
  const std::vector<Problem> problems = ValidatePlan(PlanFromJson(R"({"name": "f", "adaptive": {
    "target": {"expandedUncertainty": 2}, "budget": {},
    "region": {"thetaOMaxDeg": 95}, "seed": {"retroReadings": 101}, "roundReadings": 1001,
    "sampleFixed": {}}})"),
                                                     RigDescription{});
  for (const char* path :
       {"adaptive.target.expandedUncertainty", "adaptive.budget", "adaptive.region.thetaOMaxDeg",
        "adaptive.seed.retroReadings", "adaptive.roundReadings"}) {
    EXPECT_NE(FindProblem(problems, path), nullptr) << path << "\n" << FormatProblems(problems);
  }
}

TEST(AdaptiveSampleFixedTest, BudgetSmallerThanTheSeedsPromptsIsRefused) {
  const std::vector<Problem> problems = ValidatePlan(
      PlanFromJson(R"({"name": "f", "adaptive": {"target": {"expandedUncertainty": 0.05},
        "budget": {"maxPrompts": 10}, "sampleFixed": {}},
        "reference": {"perDetectorPosition": false}})"),
      RigDescription{});
  const Problem* p = FindProblem(problems, "adaptive.budget.maxPrompts");
  ASSERT_NE(p, nullptr) << FormatProblems(problems);
  EXPECT_THAT(p->message, HasSubstr("seed design"));
}

TEST(AdaptiveSampleFixedTest, ARegionWithNoWholeDegreePairIsNamed) {
  const std::vector<Problem> problems = ValidatePlan(PlanFromJson(Fixed(R"(,
    "region": {"thetaIMinDeg": 10.2, "thetaIMaxDeg": 10.4}, "seed": {"retroReadings": 0})")),
                                                     RigDescription{});
  const Problem* p = FindProblem(problems, "adaptive.region");
  ASSERT_NE(p, nullptr) << FormatProblems(problems);
  EXPECT_THAT(p->message, HasSubstr("whole degrees"));
}

TEST(AdaptiveSampleFixedTest, TheRigsTravelDoesNotLimitIt) {
  // The holder never moves: an α travel of 10° (which the rotation form's seed would be held to)
  // leaves the sample-fixed seed as it is.
  RigDescription narrow;
  narrow.alpha = {0, 10, 10};
  const v1::Plan plan = PlanFromJson(Fixed(""));
  const PlanAnalysis a = AnalyzePlan(plan, narrow);
  ASSERT_TRUE(a.valid()) << FormatProblems(a.problems);
  EXPECT_EQ(a.steps.size(), AnalyzePlan(plan, RigDescription{}).steps.size());
  bool beyond = false;
  for (const Step& s : OfKind(a.steps, v1::STEP_KIND_SAMPLE)) beyond |= s.pose.alpha > 10;
  EXPECT_TRUE(beyond);
}

TEST(AdaptiveSampleFixedTest, RoundTripsThroughJsonAndOldPlansStayRotation) {
  const v1::Plan plan = PlanFromJson(Fixed(R"(, "seed": {"retroReadings": 0})"));
  ASSERT_TRUE(plan.adaptive().has_sample_fixed());
  Result<std::string> json = PlanToJson(plan);
  ASSERT_TRUE(json.ok());
  EXPECT_THAT(*json, HasSubstr("\"sampleFixed\""));
  EXPECT_EQ(PlanFromJson(*json).SerializeAsString(), plan.SerializeAsString());
  // Without sampleFixed: the sample-rotation rig, as before.
  const v1::Plan rotation = PlanFromJson(R"({"name": "r", "adaptive": {
    "target": {"expandedUncertainty": 0.05}, "budget": {"maxReadings": 400}}})");
  EXPECT_FALSE(rotation.adaptive().has_sample_fixed());
  const std::vector<Step> steps = testing::Expand(rotation);
  EXPECT_FALSE(Prompts(steps, v1::PROMPT_KIND_RELOCATE_DETECTOR).empty());
  EXPECT_TRUE(Prompts(steps, v1::PROMPT_KIND_RELOCATE_LAMP_AND_DETECTOR).empty());
}

}  // namespace
}  // namespace brdf::plan
