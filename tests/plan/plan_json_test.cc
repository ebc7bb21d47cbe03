// Plan files: parsing, errors that say where, round trips.
#include "core/plan/plan_json.h"

#include <gmock/gmock.h>
#include <google/protobuf/util/message_differencer.h>
#include <gtest/gtest.h>

#include <string>

#include "core/plan/json_locator.h"

namespace brdf::plan {
namespace {

using ::testing::HasSubstr;

TEST(PlanJsonTest, ParsesLowerCamelAndProtoNames) {
  const Result<v1::Plan> a = ParsePlanJson(R"({"sampleRotation": {"alpha": {"step": 5}},
                                               "reference": {"everyNReadings": 7}})");
  ASSERT_TRUE(a.ok()) << a.status().ToString();
  EXPECT_TRUE(a->has_sample_rotation());
  EXPECT_TRUE(a->sample_rotation().alpha().has_step());
  EXPECT_FALSE(a->sample_rotation().alpha().has_start());  // unset stays unset
  EXPECT_EQ(a->sample_rotation().alpha().step(), 5);
  EXPECT_EQ(a->reference().every_n_readings(), 7u);
  const Result<v1::Plan> b = ParsePlanJson(R"({"sample_rotation": {"alpha": {"step": 5}}})");
  ASSERT_TRUE(b.ok()) << b.status().ToString();
  EXPECT_EQ(b->sample_rotation().alpha().step(), 5);
}

TEST(PlanJsonTest, RoundTrip) {
  v1::Plan plan;
  plan.set_name("round trip");
  plan.set_sample_description("ceramic tile, glaze side up");
  plan.set_anisotropic(true);
  auto* fixed = plan.mutable_sample_fixed();
  auto* t = fixed->add_targets();
  t->set_theta_i(0);  // explicitly zero: must survive (optional field)
  t->set_theta_o(45);
  t->set_phi(180);
  t->set_label("0/45");
  auto* u = fixed->add_targets();
  u->set_theta_i(30);
  u->set_phi_i(-10);
  u->set_theta_o(20);
  u->set_phi_o(100);
  plan.mutable_reference()->set_per_detector_position(false);
  plan.mutable_reference()->mutable_pose()->set_beta(0);
  plan.mutable_retry()->set_backoff_ms(0);
  plan.mutable_measurement()->set_integration_ms(250);
  const Result<std::string> json = PlanToJson(plan);
  ASSERT_TRUE(json.ok());
  EXPECT_THAT(*json, HasSubstr("\"thetaI\": 0"));
  EXPECT_THAT(*json, HasSubstr("\"perDetectorPosition\": false"));
  const Result<v1::Plan> back = ParsePlanJson(*json);
  ASSERT_TRUE(back.ok()) << back.status().ToString();
  EXPECT_TRUE(google::protobuf::util::MessageDifferencer::Equals(plan, *back))
      << *json << "\n---\n"
      << back->DebugString();
}

TEST(PlanJsonTest, UnknownFieldNamesPathAndPosition) {
  const Result<v1::Plan> r = ParsePlanJson(
      "{\n"
      "  \"sampleRotation\": {\n"
      "    \"alpa\": {\"step\": 10}\n"
      "  }\n"
      "}\n");
  ASSERT_FALSE(r.ok());
  EXPECT_EQ(r.status().code(), StatusCode::kInvalidArgument);
  EXPECT_THAT(r.status().message(), HasSubstr("line 3, column 5"));
  EXPECT_THAT(r.status().message(), HasSubstr("sampleRotation.alpa"));
  EXPECT_THAT(r.status().message(), HasSubstr("unknown field \"alpa\""));
}

TEST(PlanJsonTest, UnknownFieldInsideAnArray) {
  const Result<v1::Plan> r =
      ParsePlanJson(R"({"sampleFixed": {"targets": [{"thetaI": 1}, {"thetaI": 2, "bogus": 3}]}})");
  ASSERT_FALSE(r.ok());
  EXPECT_THAT(r.status().message(), HasSubstr("sampleFixed.targets[1].bogus"));
  EXPECT_THAT(r.status().message(), HasSubstr("line 1, column 59"));
}

TEST(PlanJsonTest, WrongTypeNamesTheField) {
  const Result<v1::Plan> r = ParsePlanJson("{\"measurement\": {\n  \"averages\": -1\n}}");
  ASSERT_FALSE(r.ok());
  EXPECT_THAT(r.status().message(), HasSubstr("measurement.averages"));
  EXPECT_THAT(r.status().message(), HasSubstr("line 2, column 3"));
  const Result<v1::Plan> s = ParsePlanJson(R"({"sampleRotation": {"alpha": {"step": "ten"}}})");
  ASSERT_FALSE(s.ok());
  EXPECT_THAT(s.status().message(), HasSubstr("sampleRotation.alpha.step"));
}

TEST(PlanJsonTest, SyntaxErrorsGiveLineAndColumn) {
  const Result<v1::Plan> r = ParsePlanJson("{\n  \"name\": \"x\",\n  \"sampleRotation\": {},,\n}");
  ASSERT_FALSE(r.ok());
  EXPECT_THAT(r.status().message(), HasSubstr("line 3, column 24"));
  EXPECT_THAT(r.status().message(), HasSubstr("member name"));
  const Result<v1::Plan> unterminated = ParsePlanJson("{\"name\": \"x");
  ASSERT_FALSE(unterminated.ok());
  EXPECT_THAT(unterminated.status().message(), HasSubstr("unterminated string"));
  const Result<v1::Plan> not_object = ParsePlanJson("[1, 2]");
  ASSERT_FALSE(not_object.ok());
  const Result<v1::Plan> empty = ParsePlanJson("");
  ASSERT_FALSE(empty.ok());
}

TEST(PlanJsonTest, TwoMethodsAreRefused) {
  const Result<v1::Plan> r = ParsePlanJson(R"({"sampleRotation": {}, "poseList": {}})");
  ASSERT_FALSE(r.ok());
  EXPECT_THAT(r.status().message(), HasSubstr("method"));
}

TEST(PlanJsonTest, SizeCap) {
  std::string huge = "{\"name\": \"";
  huge.append(kMaxPlanJsonBytes, 'x');
  huge += "\"}";
  const Result<v1::Plan> r = ParsePlanJson(huge);
  ASSERT_FALSE(r.ok());
  EXPECT_THAT(r.status().message(), HasSubstr("cap"));
}

TEST(JsonLocatorTest, PositionsCountCharactersNotBytes) {
  const JsonLocator loc("{\"name\": \"δδ\", \"x\": {\"y\": [1, {\"z\": 2}]}}");
  ASSERT_FALSE(loc.error().has_value());
  EXPECT_EQ(loc.Find("x"), (TextPosition{1, 16}));
  EXPECT_EQ(loc.Find("x.y[1].z"), (TextPosition{1, 32}));
  EXPECT_FALSE(loc.Find("x.w").has_value());
}

TEST(JsonLocatorTest, SnakeCaseKeysAreFoundByJsonPath) {
  EXPECT_EQ(ToJsonPath("sample_fixed.targets[3].theta_i"), "sampleFixed.targets[3].thetaI");
  const JsonLocator loc("{\"sample_fixed\": {}}");
  EXPECT_EQ(loc.Find("sampleFixed"), (TextPosition{1, 2}));
}

TEST(JsonLocatorTest, DeepNestingIsRefused) {
  std::string deep(JsonLocator::kMaxDepth + 2, '[');
  const JsonLocator loc(deep);
  ASSERT_TRUE(loc.error().has_value());
  EXPECT_THAT(loc.error()->message, HasSubstr("nested"));
}

}  // namespace
}  // namespace brdf::plan
