// The estimate's words for an adaptive plan's bounds.
#include "core/adaptive/budget_text.h"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include "core/plan/plan_json.h"

namespace brdf::adaptive {
namespace {

using ::testing::HasSubstr;
using ::testing::Not;

v1::Adaptive FromJson(const std::string& adaptive) {
  Result<v1::Plan> plan = plan::ParsePlanJson(R"({"adaptive": )" + adaptive + "}");
  EXPECT_TRUE(plan.ok()) << plan.status().ToString();
  return plan.ok() ? plan->adaptive() : v1::Adaptive();
}

TEST(AdaptiveBoundsTextTest, StatesEveryLimitAndTheTarget) {
  const std::string text = AdaptiveBoundsText(FromJson(R"({
    "target": {"expandedUncertainty": 0.05},
    "budget": {"maxReadings": 464, "maxRigMinutes": 40, "maxPrompts": 60}})"));
  EXPECT_THAT(text, HasSubstr("expanded uncertainty (k = 2) is at most 5 %"));
  EXPECT_THAT(
      text,
      HasSubstr("at most 464 readings, 40 min of rig time (prompts included) and 60 prompts"));
  EXPECT_THAT(text, HasSubstr("rounds of up to 24 readings"));
  EXPECT_THAT(text, Not(HasSubstr("unset")));
}

TEST(AdaptiveBoundsTextTest, SaysWhatIsLeftUnbounded) {
  const std::string text = AdaptiveBoundsText(FromJson(R"({
    "target": {"expectedError": 0.1}, "budget": {"maxRigMinutes": 30}, "roundReadings": 10})"));
  EXPECT_THAT(text, HasSubstr("expected error is at most 10 %"));
  EXPECT_THAT(text, HasSubstr("at most 30 min of rig time (prompts included) in all"));
  EXPECT_THAT(text, HasSubstr("unset is bounded only by the rest"));
}

TEST(AdaptiveBoundsTextTest, SampleFixedFormSaysWhatAPoseCostsInPrompts) {
  Result<v1::Plan> by_time = plan::ParsePlanJson(R"({"adaptive": {
    "target": {"expandedUncertainty": 0.05}, "budget": {"maxPrompts": 120}, "sampleFixed": {}},
    "reference": {"perDetectorPosition": false, "everyMinutes": 15}})");
  ASSERT_TRUE(by_time.ok()) << by_time.status().ToString();
  const std::string text = AdaptiveBoundsText(*by_time);
  EXPECT_THAT(text, HasSubstr("at most 120 prompts in all (seed included)"));
  EXPECT_THAT(text, HasSubstr("only by the rest; sample-fixed: each pose is 1 prompt (lamp and "
                              "detector set by hand)"));
  v1::Plan per_target = *by_time;
  per_target.mutable_reference()->set_per_detector_position(true);
  EXPECT_THAT(AdaptiveBoundsText(per_target), HasSubstr("each pose is 3 prompts"));
  // The rotation form: the text of its adaptive message alone.
  per_target.mutable_adaptive()->clear_sample_fixed();
  EXPECT_EQ(AdaptiveBoundsText(per_target), AdaptiveBoundsText(per_target.adaptive()));
}

}  // namespace
}  // namespace brdf::adaptive
