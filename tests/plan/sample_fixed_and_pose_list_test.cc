// Expansion of sample-fixed plans (operator relocates lamp and detector per target) and of
// explicit pose lists.
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <cmath>

#include "core/geometry.h"
#include "core/plan/analyze_plan.h"
#include "plan_test_util.h"

namespace brdf::plan {
namespace {

using testing::Expand;
using ::testing::HasSubstr;
using testing::OfKind;
using testing::PlanFromJson;
using testing::Prompts;

double AngleGap(double a, double b) {
  return std::fabs(std::remainder(a - b, 360.0));
}

TEST(SampleFixedTest, EachTargetIsARelocationPromptThenASampleReading) {
  const v1::Plan plan = PlanFromJson(R"({
    "sampleFixed": {"targets": [
      {"thetaI": 30, "thetaO": 45, "phi": 180, "label": "near specular"},
      {"thetaI": 60, "thetaO": 20, "phi": 90},
      {"thetaI": 0, "thetaO": 45, "phi": 0}
    ]},
    "reference": {"perDetectorPosition": false}
  })");
  const std::vector<Step> steps = Expand(plan);
  EXPECT_TRUE(OfKind(steps, v1::STEP_KIND_MOVE).empty());  // the sample never moves
  const std::vector<Step> relocations = Prompts(steps, v1::PROMPT_KIND_RELOCATE_LAMP_AND_DETECTOR);
  const std::vector<Step> samples = OfKind(steps, v1::STEP_KIND_SAMPLE);
  ASSERT_EQ(relocations.size(), 3u);
  ASSERT_EQ(samples.size(), 3u);
  // One reference, before the first sample reading only (per-detector references are off).
  EXPECT_EQ(OfKind(steps, v1::STEP_KIND_REFERENCE).size(), 1u);

  EXPECT_THAT(relocations[0].prompt_text, HasSubstr("θi = 30°"));
  EXPECT_THAT(relocations[0].prompt_text, HasSubstr("θo = 45°"));
  EXPECT_THAT(relocations[0].prompt_text, HasSubstr("φ = 180°"));
  EXPECT_THAT(relocations[0].prompt_text, HasSubstr("near specular"));
  EXPECT_THAT(relocations[1].prompt_text, HasSubstr("target 2 of 3"));

  const IsoDirection wanted[] = {{30, 45, 180}, {60, 20, 90}, {0, 45, 0}};
  for (int i = 0; i < 3; ++i) {
    ASSERT_TRUE(samples[i].target.has_value());
    const IsoDirection got = ToIsotropic(*samples[i].target);
    EXPECT_EQ(got, wanted[i]);
    // The step's pose is the equivalent pose by inverse kinematics.
    const IsoDirection via_pose = ToIsotropic(PoseToDirections(samples[i].pose));
    EXPECT_NEAR(via_pose.theta_i, wanted[i].theta_i, 1e-9);
    EXPECT_NEAR(via_pose.theta_o, wanted[i].theta_o, 1e-9);
    EXPECT_NEAR(via_pose.phi, wanted[i].phi, 1e-9);
    EXPECT_EQ(relocations[i].target, samples[i].target);
  }
  // Each relocation comes right before its sample (no reference block in between but the first).
  EXPECT_EQ(steps.back().kind, v1::STEP_KIND_SAMPLE);
  EXPECT_EQ(steps[steps.size() - 2].prompt, v1::PROMPT_KIND_RELOCATE_LAMP_AND_DETECTOR);
}

TEST(SampleFixedTest, PerDetectorPositionReferencesAreTakenAtEachTarget) {
  const v1::Plan plan = PlanFromJson(R"({
    "sampleFixed": {"targets": [
      {"thetaI": 30, "thetaO": 45, "phi": 180}, {"thetaI": 50, "thetaO": 10, "phi": 45}
    ]},
    "dark": {"withEachReference": true}
  })");
  const std::vector<Step> steps = Expand(plan);
  const std::vector<Step> refs = OfKind(steps, v1::STEP_KIND_REFERENCE);
  ASSERT_EQ(refs.size(), 2u);
  EXPECT_EQ(OfKind(steps, v1::STEP_KIND_DARK).size(), 2u);
  // A sample-fixed reference is taken where lamp and detector stand: θi,ref = the target's θi.
  EXPECT_NEAR(refs[0].target->theta_i, 30, 1e-9);
  EXPECT_NEAR(refs[1].target->theta_i, 50, 1e-9);
  // Order per target: relocate, mount white, reference, close shutter, dark, mount sample, sample.
  const PromptKind p = v1::PROMPT_KIND_UNSPECIFIED;
  const std::vector<std::pair<StepKind, PromptKind>> expected = {
      {v1::STEP_KIND_PROMPT, v1::PROMPT_KIND_RELOCATE_LAMP_AND_DETECTOR},
      {v1::STEP_KIND_PROMPT, v1::PROMPT_KIND_MOUNT_WHITE},
      {v1::STEP_KIND_REFERENCE, p},
      {v1::STEP_KIND_PROMPT, v1::PROMPT_KIND_CLOSE_SHUTTER},
      {v1::STEP_KIND_DARK, p},
      {v1::STEP_KIND_PROMPT, v1::PROMPT_KIND_MOUNT_SAMPLE},
      {v1::STEP_KIND_SAMPLE, p}};
  ASSERT_EQ(steps.size(), 2 * expected.size());
  for (std::size_t i = 0; i < steps.size(); ++i) {
    EXPECT_EQ(steps[i].kind, expected[i % expected.size()].first) << i;
    EXPECT_EQ(steps[i].prompt, expected[i % expected.size()].second) << i;
  }
}

TEST(SampleFixedTest, FourAngleTargetsKeepTheirAzimuths) {
  const v1::Plan plan = PlanFromJson(R"({
    "anisotropic": true,
    "sampleFixed": {"targets": [
      {"thetaI": 40, "phiI": 30, "thetaO": 25, "phiO": 150},
      {"thetaI": 0, "phiI": 0, "thetaO": 35, "phiO": -60},
      {"thetaI": 50, "phiI": 100, "thetaO": 60, "phiO": -20}
    ]}
  })");
  const std::vector<Step> samples = OfKind(Expand(plan), v1::STEP_KIND_SAMPLE);
  ASSERT_EQ(samples.size(), 3u);
  EXPECT_EQ(*samples[0].target, (Directions{40, 30, 25, 150}));
  // The equivalent pose (with γ) reproduces all four angles.
  const Directions d0 = PoseToDirections(samples[0].pose);
  EXPECT_NEAR(d0.theta_i, 40, 1e-9);
  EXPECT_NEAR(d0.theta_o, 25, 1e-9);
  EXPECT_LT(AngleGap(d0.phi_i, 30), 1e-6);
  EXPECT_LT(AngleGap(d0.phi_o, 150), 1e-6);
  const Directions d1 = PoseToDirections(samples[1].pose);
  EXPECT_NEAR(d1.theta_o, 35, 1e-9);
  EXPECT_LT(AngleGap(d1.phi_o, -60), 1e-6);
  // φo − φi = −120°: the mirror image of what α ≥ 0 reaches.
  const Directions d2 = PoseToDirections(samples[2].pose);
  EXPECT_NEAR(d2.theta_i, 50, 1e-9);
  EXPECT_NEAR(d2.theta_o, 60, 1e-9);
  EXPECT_LT(AngleGap(d2.phi_i, 100), 1e-6);
  EXPECT_LT(AngleGap(d2.phi_o, -20), 1e-6);
}

TEST(PoseListTest, MovesAndReadingsWithRelocationsWhenDeltaChanges) {
  const v1::Plan plan = PlanFromJson(R"({
    "poseList": {"poses": [
      {"alpha": 0, "beta": 0, "delta": 45, "label": "first"},
      {"alpha": 10, "beta": 20, "delta": 45},
      {"alpha": 0, "beta": 30, "delta": 90},
      {"alpha": 20, "beta": 40, "delta": 90}
    ]}
  })");
  const std::vector<Step> steps = Expand(plan);
  const std::vector<Step> samples = OfKind(steps, v1::STEP_KIND_SAMPLE);
  ASSERT_EQ(samples.size(), 4u);
  EXPECT_EQ(samples[0].label, "first");
  EXPECT_EQ(samples[1].pose, (Pose{10, 20, 0, 45}));
  EXPECT_EQ(samples[3].pose, (Pose{20, 40, 0, 90}));
  const std::vector<Step> relocations = Prompts(steps, v1::PROMPT_KIND_RELOCATE_DETECTOR);
  ASSERT_EQ(relocations.size(), 2u);
  EXPECT_EQ(relocations[0].pose.delta, 45);
  EXPECT_EQ(relocations[1].pose.delta, 90);
  EXPECT_EQ(OfKind(steps, v1::STEP_KIND_REFERENCE).size(), 2u);  // one per detector position
  for (std::size_t i = 1; i < steps.size(); ++i) {
    if (steps[i].kind == v1::STEP_KIND_SAMPLE) {
      EXPECT_EQ(steps[i - 1].kind, v1::STEP_KIND_MOVE);
      EXPECT_EQ(steps[i - 1].pose, steps[i].pose);
    }
  }
  EXPECT_TRUE(Prompts(steps, v1::PROMPT_KIND_SET_GAMMA_DIAL).empty());
}

TEST(PoseListTest, ManualDialPromptsOnlyWhenGammaChanges) {
  const v1::Plan plan = PlanFromJson(R"({
    "anisotropic": true,
    "poseList": {"poses": [
      {"alpha": 0, "beta": 10, "gamma": 0, "delta": 30},
      {"alpha": 0, "beta": 20, "gamma": 45, "delta": 30},
      {"alpha": 0, "beta": 30, "gamma": 45, "delta": 30}
    ]}
  })");
  const std::vector<Step> dials = Prompts(Expand(plan), v1::PROMPT_KIND_SET_GAMMA_DIAL);
  ASSERT_EQ(dials.size(), 2u);
  EXPECT_EQ(dials[0].pose.gamma, 0);
  EXPECT_EQ(dials[1].pose.gamma, 45);
}

}  // namespace
}  // namespace brdf::plan
