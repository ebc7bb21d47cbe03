// The adaptive plan kind: JSON form, validation with field paths, the seed design's steps and the
// checks of the seed against the budget.
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <string>
#include <vector>

#include "core/plan/analyze_plan.h"
#include "plan_test_util.h"

namespace brdf::plan {
namespace {

using ::testing::HasSubstr;
using testing::OfKind;
using testing::PlanFromJson;
using testing::Prompts;

const Problem* Find(const std::vector<Problem>& problems, const std::string& path) {
  for (const Problem& p : problems) {
    if (p.field_path == path) return &p;
  }
  return nullptr;
}

std::string Adaptive(const std::string& fields) {
  return R"({"name": "a", "adaptive": {)" + fields + "}}";
}

constexpr const char* kGood =
    R"("target": {"expandedUncertainty": 0.05}, "budget": {"maxReadings": 400})";

TEST(AdaptivePlanTest, ExampleIsValidAndExpandsToItsSeed) {
  std::FILE* f = std::fopen((std::string(BRDF_EXAMPLES_DIR) + "/adaptive.json").c_str(), "rb");
  ASSERT_NE(f, nullptr);
  std::string text;
  char buf[4096];
  for (std::size_t n; (n = std::fread(buf, 1, sizeof buf, f)) > 0;) text.append(buf, n);
  std::fclose(f);
  const PlanAnalysis a = AnalyzePlan(PlanFromJson(text), RigDescription{});
  ASSERT_TRUE(a.valid()) << FormatProblems(a.problems);
  // 8 retro-reflection readings and up to 21 at every fourth of the 29 detector positions (δ every
  // 5.625° to 157.5°, seeded every 22.5°: 8 positions), as many as 24 at each of 7 would be.
  EXPECT_GT(a.summary.sample_readings, 8 + 21 * 6);
  EXPECT_LE(a.summary.sample_readings, 8 + 21 * 8);
  std::vector<double> deltas;
  for (const Step& s : OfKind(a.steps, v1::STEP_KIND_SAMPLE)) {
    if (deltas.empty() || deltas.back() != s.pose.delta) deltas.push_back(s.pose.delta);
  }
  EXPECT_EQ(deltas, (std::vector<double>{0, 22.5, 45, 67.5, 90, 112.5, 135, 157.5}));
  // One relocation per seeded δ: the seed visits each of its detector positions once.
  EXPECT_EQ(Prompts(a.steps, v1::PROMPT_KIND_RELOCATE_DETECTOR).size(), 8u);
}

TEST(AdaptivePlanTest, ACheaperSeedAtEveryNthDeltaPassesItsChecksWithFewerPrompts) {
  const std::string fields = std::string(kGood) + R"(,
    "delta": {"start": 0, "stop": 146.25, "step": 11.25},
    "seed": {"readingsPerDelta": 24)";
  const PlanAnalysis every = AnalyzePlan(PlanFromJson(Adaptive(fields + "}")), RigDescription{});
  const PlanAnalysis cheap =
      AnalyzePlan(PlanFromJson(Adaptive(fields + R"(, "deltaEvery": 4})")), RigDescription{});
  ASSERT_TRUE(every.valid()) << FormatProblems(every.problems);
  ASSERT_TRUE(cheap.valid()) << FormatProblems(cheap.problems);
  // δ = 0, 45, 90 and 135: four relocations, not 14, and a quarter of the rig time or so.
  std::vector<double> deltas;
  for (const Step& s : OfKind(cheap.steps, v1::STEP_KIND_SAMPLE)) {
    if (deltas.empty() || deltas.back() != s.pose.delta) deltas.push_back(s.pose.delta);
  }
  EXPECT_EQ(deltas.size(), 4u);
  EXPECT_EQ(Prompts(cheap.steps, v1::PROMPT_KIND_RELOCATE_DETECTOR).size(), 4u);
  EXPECT_EQ(Prompts(every.steps, v1::PROMPT_KIND_RELOCATE_DETECTOR).size(), 14u);
  EXPECT_LT(cheap.summary.operator_interventions * 3, every.summary.operator_interventions);
  EXPECT_LT(cheap.summary.estimated_duration_s * 2, every.summary.estimated_duration_s);
  // The budget checks see the cheaper seed: a budget between the two passes.
  const std::string budget = R"("target": {"expandedUncertainty": 0.05},
    "budget": {"maxPrompts": )" +
                             std::to_string(every.summary.operator_interventions - 1) + "}";
  const std::string rest = R"(,
    "delta": {"start": 0, "stop": 146.25, "step": 11.25}, "seed": {"readingsPerDelta": 24)";
  EXPECT_NE(Find(ValidatePlan(PlanFromJson(Adaptive(budget + rest + "}")), RigDescription{}),
                 "adaptive.budget.maxPrompts"),
            nullptr);
  EXPECT_TRUE(ValidatePlan(PlanFromJson(Adaptive(budget + rest + R"(, "deltaEvery": 4})")),
                           RigDescription{})
                  .empty());
}

TEST(AdaptivePlanTest, SeedStaysInTheRegionAndTravel) {
  const v1::Plan plan = PlanFromJson(Adaptive(std::string(kGood) + R"(,
    "region": {"thetaIMinDeg": 10, "thetaIMaxDeg": 60, "thetaOMaxDeg": 70},
    "delta": {"start": 0, "stop": 90, "step": 30})"));
  RigDescription rig;
  rig.alpha = {0, 50, 10};
  const std::vector<Step> steps = testing::Expand(plan, rig);
  const std::vector<Step> samples = OfKind(steps, v1::STEP_KIND_SAMPLE);
  ASSERT_FALSE(samples.empty());
  for (const Step& s : samples) {
    ASSERT_TRUE(s.target.has_value());
    EXPECT_GE(s.target->theta_i, 10 - 1e-9) << s.label;
    EXPECT_LE(s.target->theta_i, 60 + 1e-9) << s.label;
    EXPECT_LE(s.target->theta_o, 70 + 1e-9) << s.label;
    EXPECT_LE(s.pose.alpha, 50 + 1e-9) << s.label;
  }
  // The retro-reflection scan comes first, at δ = 0 with θi = θo.
  EXPECT_THAT(samples.front().label, HasSubstr("retro-reflection"));
  EXPECT_NEAR(samples.front().target->theta_i, samples.front().target->theta_o, 1e-9);
}

TEST(AdaptivePlanTest, SeedIsDeterministic) {
  const v1::Plan plan = PlanFromJson(Adaptive(kGood));
  const std::vector<Step> a = testing::Expand(plan);
  const std::vector<Step> b = testing::Expand(plan);
  ASSERT_EQ(a.size(), b.size());
  for (std::size_t i = 0; i < a.size(); ++i) {
    EXPECT_EQ(a[i].pose, b[i].pose);
    EXPECT_EQ(a[i].label, b[i].label);
  }
}

TEST(AdaptivePlanTest, MissingTargetAndBudgetAreNamed) {
  const std::vector<Problem> problems =
      ValidatePlan(PlanFromJson(Adaptive(R"("roundReadings": 10)")), RigDescription{});
  const Problem* target = Find(problems, "adaptive.target");
  ASSERT_NE(target, nullptr) << FormatProblems(problems);
  EXPECT_THAT(target->message, HasSubstr("expandedUncertainty"));
  const Problem* budget = Find(problems, "adaptive.budget");
  ASSERT_NE(budget, nullptr) << FormatProblems(problems);
  EXPECT_THAT(budget->message, HasSubstr("maxReadings, maxRigMinutes, maxPrompts"));
}

TEST(AdaptivePlanTest, BadValuesAreNamedWithTheirPaths) {
  const std::vector<Problem> problems = ValidatePlan(PlanFromJson(Adaptive(R"(
        "target": {"expandedUncertainty": 0.05, "expectedError": 0.1},
        "budget": {"maxRigMinutes": -3},
        "region": {"thetaIMinDeg": 50, "thetaIMaxDeg": 40, "thetaOMaxDeg": 95},
        "delta": {"step": 0},
        "gamma": [0, 0],
        "seed": {"retroReadings": 101, "readingsPerDelta": 501, "deltaEvery": 101},
        "roundReadings": 1001)")),
                                                     RigDescription{});
  for (const char* path :
       {"adaptive.target", "adaptive.budget.maxRigMinutes", "adaptive.region.thetaIMaxDeg",
        "adaptive.region.thetaOMaxDeg", "adaptive.delta.step", "adaptive.gamma[1]",
        "adaptive.seed.retroReadings", "adaptive.seed.readingsPerDelta", "adaptive.seed.deltaEvery",
        "adaptive.roundReadings"}) {
    EXPECT_NE(Find(problems, path), nullptr) << path << "\n" << FormatProblems(problems);
  }
  EXPECT_THAT(Find(problems, "adaptive.target")->message, HasSubstr("not both"));
}

TEST(AdaptivePlanTest, TargetLevelMustBeRelative) {
  const std::vector<Problem> problems = ValidatePlan(
      PlanFromJson(Adaptive(R"("target": {"expectedError": 5}, "budget": {"maxPrompts": 90})")),
      RigDescription{});
  const Problem* p = Find(problems, "adaptive.target.expectedError");
  ASSERT_NE(p, nullptr) << FormatProblems(problems);
  EXPECT_THAT(p->message, HasSubstr("(0, 1]"));
}

TEST(AdaptivePlanTest, BudgetSmallerThanTheSeedIsRefused) {
  const std::vector<Problem> problems = ValidatePlan(PlanFromJson(Adaptive(
                                                         R"("target": {"expandedUncertainty": 0.05},
             "budget": {"maxReadings": 20, "maxRigMinutes": 1, "maxPrompts": 3})")),
                                                     RigDescription{});
  const Problem* readings = Find(problems, "adaptive.budget.maxReadings");
  ASSERT_NE(readings, nullptr) << FormatProblems(problems);
  EXPECT_THAT(readings->message, HasSubstr("seed design"));
  // Prompts and time are checked on the seed's steps, once the readings fit.
  const std::vector<Problem> steps_problems =
      ValidatePlan(PlanFromJson(Adaptive(
                       R"("target": {"expandedUncertainty": 0.05},
             "budget": {"maxRigMinutes": 1, "maxPrompts": 3})")),
                   RigDescription{});
  EXPECT_NE(Find(steps_problems, "adaptive.budget.maxRigMinutes"), nullptr)
      << FormatProblems(steps_problems);
  EXPECT_NE(Find(steps_problems, "adaptive.budget.maxPrompts"), nullptr)
      << FormatProblems(steps_problems);
}

TEST(AdaptivePlanTest, UnreachableDetectorPositionIsNamed) {
  // Both polar angles at most 30°: the lamp–detector angle cannot exceed 60°.
  const std::vector<Problem> problems = ValidatePlan(PlanFromJson(Adaptive(std::string(kGood) + R"(,
        "region": {"thetaIMaxDeg": 30, "thetaOMaxDeg": 30},
        "delta": {"start": 0, "stop": 90, "step": 45})")),
                                                     RigDescription{});
  const Problem* p = Find(problems, "adaptive.delta");
  ASSERT_NE(p, nullptr) << FormatProblems(problems);
  EXPECT_THAT(p->message, HasSubstr("δ = 90°"));
}

TEST(AdaptivePlanTest, SeedSizeIsCapped) {
  std::vector<Problem> problems = ValidatePlan(
      PlanFromJson(Adaptive(std::string(kGood) + R"(, "delta": {"step": 0.1})")), RigDescription{});
  const Problem* settings = Find(problems, "adaptive.delta");
  ASSERT_NE(settings, nullptr) << FormatProblems(problems);
  EXPECT_THAT(settings->message, HasSubstr("δ × γ"));
  problems = ValidatePlan(PlanFromJson(Adaptive(std::string(kGood) + R"(,
      "gamma": [0, 45, 90], "seed": {"readingsPerDelta": 500})")),
                          RigDescription{});
  const Problem* readings = Find(problems, "adaptive.seed.readingsPerDelta");
  ASSERT_NE(readings, nullptr) << FormatProblems(problems);
  EXPECT_THAT(readings->message, HasSubstr("21000 seed readings"));
}

TEST(AdaptivePlanTest, RoundTripsThroughJson) {
  const v1::Plan plan = PlanFromJson(Adaptive(std::string(kGood) + R"(,
    "method": "ADAPTIVE_JUDGE_DELAUNAY", "gamma": [0, 45], "seed": {"retroReadings": 0})"));
  ASSERT_TRUE(plan.has_adaptive());
  EXPECT_EQ(plan.adaptive().method(), v1::ADAPTIVE_JUDGE_DELAUNAY);
  EXPECT_TRUE(plan.adaptive().seed().has_retro_readings());
  Result<std::string> json = PlanToJson(plan);
  ASSERT_TRUE(json.ok());
  EXPECT_THAT(*json, HasSubstr("\"retroReadings\": 0"));
  EXPECT_EQ(PlanFromJson(*json).SerializeAsString(), plan.SerializeAsString());
}

}  // namespace
}  // namespace brdf::plan
