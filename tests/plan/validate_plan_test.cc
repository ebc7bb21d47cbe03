// ValidatePlan: every problem at once, each with the JSON path of its field.
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <algorithm>
#include <limits>
#include <string>
#include <vector>

#include "core/plan/analyze_plan.h"
#include "core/plan/sample.h"
#include "plan_test_util.h"

namespace brdf::plan {
namespace {

using ::testing::HasSubstr;
using testing::PlanFromJson;
using ::testing::UnorderedElementsAreArray;

std::vector<std::string> Paths(const std::vector<Problem>& problems) {
  std::vector<std::string> out;
  for (const Problem& p : problems) out.push_back(p.field_path);
  return out;
}

const Problem* Find(const std::vector<Problem>& problems, const std::string& path) {
  for (const Problem& p : problems) {
    if (p.field_path == path) return &p;
  }
  return nullptr;
}

TEST(ValidatePlanTest, ExamplePlansAreValid) {
  for (const char* name : {"paper-grid.json", "demo.json", "sample-fixed.json", "pose-list.json"}) {
    SCOPED_TRACE(name);
    std::FILE* f = std::fopen((std::string(BRDF_EXAMPLES_DIR) + "/" + name).c_str(), "rb");
    ASSERT_NE(f, nullptr);
    std::string text;
    char buf[4096];
    for (std::size_t n; (n = std::fread(buf, 1, sizeof buf, f)) > 0;) text.append(buf, n);
    std::fclose(f);
    const PlanAnalysis a = AnalyzePlan(PlanFromJson(text), RigDescription{});
    EXPECT_TRUE(a.valid()) << FormatProblems(a.problems);
    EXPECT_GT(a.summary.sample_readings, 0);
  }
}

TEST(ValidatePlanTest, WhiteReflectanceUncertaintyIsCheckedAndGiven) {
  const v1::Plan good = PlanFromJson(R"({
    "name": "u", "poseList": {"poses": [{"alpha": 10, "beta": 0, "delta": 30}]},
    "sample": {"whiteReflectance": 0.99, "whiteReflectanceUncertainty": 0.005}
  })");
  EXPECT_TRUE(ValidatePlan(good, RigDescription{}).empty())
      << FormatProblems(ValidatePlan(good, RigDescription{}));
  EXPECT_EQ(WhiteReflectanceUncertaintyOf(good), 0.005);
  const v1::Plan none = PlanFromJson(R"({
    "name": "u", "poseList": {"poses": [{"alpha": 10, "beta": 0, "delta": 30}]},
    "sample": {"whiteReflectance": 0.99}
  })");
  EXPECT_FALSE(WhiteReflectanceUncertaintyOf(none).has_value());
  for (const char* value : {"-0.001", "0.51", "2"}) {
    const v1::Plan bad = PlanFromJson(std::string(R"({
      "name": "u", "poseList": {"poses": [{"alpha": 10, "beta": 0, "delta": 30}]},
      "sample": {"whiteReflectanceUncertainty": )") +
                                      value + "}}");
    const std::vector<Problem> problems = ValidatePlan(bad, RigDescription{});
    ASSERT_EQ(problems.size(), 1u) << value;
    EXPECT_EQ(problems[0].field_path, "sample.whiteReflectanceUncertainty");
    EXPECT_THAT(problems[0].message, HasSubstr("[0, 0.5]"));
  }
}

TEST(ValidatePlanTest, SampleBlockIsCheckedAndGivesRhoW) {
  const v1::Plan good = PlanFromJson(R"({
    "name": "gloss", "poseList": {"poses": [{"alpha": 10, "beta": 0, "delta": 30}]},
    "sample": {"id": "P-0042", "name": "red gloss", "material": "paint", "tags": ["glossy"],
               "whiteStandardId": "RS-3 #1187",
               "whiteReflectanceSpectrum": {"startNm": 380, "stepNm": 100, "values": [0.97, 0.98, 0.99, 0.99, 0.99]}}
  })");
  EXPECT_TRUE(ValidatePlan(good, RigDescription{}).empty())
      << FormatProblems(ValidatePlan(good, RigDescription{}));
  std::optional<Spectrum> white = WhiteReflectanceSpectrumOf(good);
  ASSERT_TRUE(white.has_value());
  EXPECT_EQ(white->grid.count, 5u);
  EXPECT_DOUBLE_EQ(white->grid.last_nm(), 780);
  EXPECT_FALSE(WhiteReflectanceOf(good).has_value());  // the spectrum wins

  const v1::Plan bad = PlanFromJson(R"({
    "name": "gloss", "poseList": {"poses": [{"alpha": 10, "beta": 0, "delta": 30}]},
    "sample": {"tags": ["ok", ""], "whiteReflectance": 1.5,
               "whiteReflectanceSpectrum": {"startNm": 380, "stepNm": 0, "values": [2.0]}}
  })");
  const std::vector<Problem> problems = ValidatePlan(bad, RigDescription{});
  EXPECT_THAT(
      Paths(problems),
      UnorderedElementsAreArray(
          {"sample.tags[1]", "sample.whiteReflectance", "sample.whiteReflectanceSpectrum.stepNm",
           "sample.whiteReflectanceSpectrum.values", "sample.whiteReflectanceSpectrum.values"}));

  const v1::Plan number = PlanFromJson(R"({
    "name": "n", "poseList": {"poses": [{"alpha": 10, "beta": 0, "delta": 30}]},
    "sample": {"whiteReflectance": 0.97}
  })");
  EXPECT_EQ(WhiteReflectanceOf(number), 0.97);
}

TEST(ValidatePlanTest, SampleRotationRangeProblemsAllAtOnce) {
  const v1::Plan plan = PlanFromJson(R"({
    "name": "broken",
    "sampleRotation": {
      "delta": {"start": 0, "stop": 200, "step": 0},
      "alpha": {"start": 40, "stop": 10, "step": 10},
      "beta": {"step": -5, "thetaMaxDeg": 95},
      "gamma": [0, "NaN", 0]
    },
    "reference": {"everyMinutes": -1},
    "measurement": {"integrationMs": 5, "averages": 120},
    "retry": {"maxAttempts": 50, "backoffMultiplier": 0.5, "backoffMs": 5000, "maxBackoffMs": 100}
  })");
  const std::vector<Problem> problems = ValidatePlan(plan, RigDescription{});
  EXPECT_THAT(Paths(problems), UnorderedElementsAreArray({
                                   "sampleRotation.delta.stop",
                                   "sampleRotation.delta.step",
                                   "sampleRotation.alpha.stop",
                                   "sampleRotation.beta.step",
                                   "sampleRotation.beta.thetaMaxDeg",
                                   "sampleRotation.gamma[1]",
                                   "sampleRotation.gamma[2]",
                                   "reference.everyMinutes",
                                   "measurement.integrationMs",
                                   "measurement.averages",
                                   "retry.maxAttempts",
                                   "retry.backoffMultiplier",
                                   "retry.maxBackoffMs",
                               }))
      << FormatProblems(problems);
  EXPECT_THAT(Find(problems, "sampleRotation.delta.step")->message, HasSubstr("> 0"));
  EXPECT_THAT(Find(problems, "sampleRotation.alpha.stop")->message, HasSubstr("below start"));
  EXPECT_THAT(Find(problems, "sampleRotation.gamma[1]")->message, HasSubstr("nan"));
  EXPECT_THAT(Find(problems, "sampleRotation.gamma[2]")->message, HasSubstr("repeats gamma[0]"));
}

TEST(ValidatePlanTest, InfinitiesAndTravelLimits) {
  const v1::Plan plan = PlanFromJson(R"({
    "sampleRotation": {
      "delta": {"start": "-Infinity"},
      "alpha": {"stop": 90}
    }
  })");
  RigDescription rig;
  rig.alpha = {0, 80, 10};
  const std::vector<Problem> problems = ValidatePlan(plan, rig);
  EXPECT_THAT(Paths(problems), UnorderedElementsAreArray(
                                   {"sampleRotation.delta.start", "sampleRotation.alpha.stop"}))
      << FormatProblems(problems);
  EXPECT_THAT(Find(problems, "sampleRotation.alpha.stop")->message, HasSubstr("travel"));
}

TEST(ValidatePlanTest, BetaTravelIsCheckedOnTheExpandedGrid) {
  RigDescription rig;
  rig.beta = {-60, 75, 20};  // the automatic reference poses reach β = 71.25°
  const v1::Plan plan = PlanFromJson(R"({"sampleRotation": {}})");
  const std::vector<Problem> problems = ValidatePlan(plan, rig);
  ASSERT_EQ(problems.size(), 1u) << FormatProblems(problems);
  EXPECT_EQ(problems[0].field_path, "sampleRotation.beta");
  EXPECT_THAT(problems[0].message, HasSubstr("more like it"));  // reported once, counted
}

TEST(ValidatePlanTest, ReferencePoseThatCannotSeeTheWhite) {
  const v1::Plan plan = PlanFromJson(R"({
    "sampleRotation": {"delta": {"start": 0, "stop": 120, "step": 60}},
    "reference": {"pose": {"beta": 0}}
  })");
  const std::vector<Problem> problems = ValidatePlan(plan, RigDescription{});
  ASSERT_EQ(problems.size(), 1u) << FormatProblems(problems);
  EXPECT_EQ(problems[0].field_path, "reference.pose");
  EXPECT_THAT(problems[0].message, HasSubstr("δ = 120°"));
}

TEST(ValidatePlanTest, SampleFixedTargetsNameTheirIndex) {
  const v1::Plan plan = PlanFromJson(R"({
    "sampleFixed": {"targets": [
      {"thetaI": 30, "thetaO": 30, "phi": 180},
      {"thetaO": 30, "phi": 180},
      {"thetaI": 95, "thetaO": 30, "phi": 180},
      {"thetaI": 30, "thetaO": 30},
      {"thetaI": 30, "thetaO": 30, "phi": 10, "phiI": 0, "phiO": 10},
      {"thetaI": 30, "thetaO": 30, "phiI": 0},
      {"thetaI": 30, "thetaO": 30, "phi": 200}
    ]}
  })");
  const std::vector<Problem> problems = ValidatePlan(plan, RigDescription{});
  EXPECT_THAT(Paths(problems), UnorderedElementsAreArray({
                                   "sampleFixed.targets[1].thetaI",
                                   "sampleFixed.targets[2].thetaI",
                                   "sampleFixed.targets[3].phi",
                                   "sampleFixed.targets[4].phi",
                                   "sampleFixed.targets[5].phiO",
                                   "sampleFixed.targets[6].phi",
                               }))
      << FormatProblems(problems);
  EXPECT_THAT(Find(problems, "sampleFixed.targets[1].thetaI")->message, HasSubstr("missing"));
}

TEST(ValidatePlanTest, EmptyTargetList) {
  EXPECT_THAT(Paths(ValidatePlan(PlanFromJson(R"({"sampleFixed": {}})"), {})),
              UnorderedElementsAreArray({"sampleFixed.targets"}));
}

TEST(ValidatePlanTest, PoseListProblems) {
  const v1::Plan plan = PlanFromJson(R"({
    "poseList": {"poses": [
      {"alpha": 0, "beta": 0, "delta": 30},
      {"beta": 0, "delta": 30},
      {"alpha": 100, "beta": 0, "delta": 30},
      {"alpha": 0, "beta": 0, "delta": 190},
      {"alpha": 0, "beta": 200, "delta": 30},
      {"alpha": 0, "beta": 120, "delta": 30},
      {"alpha": 0, "beta": 0, "gamma": "Infinity", "delta": 30}
    ]}
  })");
  RigDescription rig;
  rig.beta = {-180, 180, 20};
  const std::vector<Problem> problems = ValidatePlan(plan, rig);
  EXPECT_THAT(Paths(problems), UnorderedElementsAreArray({
                                   "poseList.poses[1].alpha",
                                   "poseList.poses[2].alpha",
                                   "poseList.poses[3].delta",
                                   "poseList.poses[4].beta",
                                   "poseList.poses[5]",
                                   "poseList.poses[6].gamma",
                               }))
      << FormatProblems(problems);
  EXPECT_THAT(Find(problems, "poseList.poses[5]")->message, HasSubstr("below the sample surface"));
  EXPECT_THAT(Find(problems, "poseList.poses[4].beta")->message, HasSubstr("travel"));
}

TEST(ValidatePlanTest, NoMethod) {
  const std::vector<Problem> problems = ValidatePlan(v1::Plan(), {});
  ASSERT_EQ(problems.size(), 1u);
  EXPECT_EQ(problems[0].field_path, "method");
}

TEST(ValidatePlanTest, TooManySteps) {
  // Valid ranges, but δ every 1° × α every 1° × β every 1°: far beyond the cap.
  const v1::Plan plan = PlanFromJson(R"({
    "sampleRotation": {"delta": {"step": 1}, "alpha": {"step": 1}, "beta": {"step": 1}}
  })");
  const std::vector<Problem> problems = ValidatePlan(plan, {});
  ASSERT_EQ(problems.size(), 1u) << FormatProblems(problems);
  EXPECT_EQ(problems[0].field_path, "");
  // A grid just over the cap after expansion (examined, then refused).
  const v1::Plan big = PlanFromJson(R"({
    "sampleRotation": {"delta": {"step": 2.5}, "alpha": {"step": 2}, "beta": {"step": 1}}
  })");
  const std::vector<Problem> big_problems = ValidatePlan(big, {});
  ASSERT_EQ(big_problems.size(), 1u) << FormatProblems(big_problems);
  EXPECT_THAT(big_problems[0].message, HasSubstr(std::to_string(kMaxSteps)));
}

TEST(ValidatePlanTest, ExpandPlanRefusesAnInvalidPlanListingEveryProblem) {
  const v1::Plan plan = PlanFromJson(R"({
    "sampleRotation": {"alpha": {"step": 0}},
    "measurement": {"averages": 500}
  })");
  const Result<std::vector<Step>> steps = ExpandPlan(plan, {});
  ASSERT_FALSE(steps.ok());
  EXPECT_EQ(steps.status().code(), StatusCode::kInvalidArgument);
  EXPECT_THAT(steps.status().message(), HasSubstr("sampleRotation.alpha.step"));
  EXPECT_THAT(steps.status().message(), HasSubstr("measurement.averages"));
}

}  // namespace
}  // namespace brdf::plan
