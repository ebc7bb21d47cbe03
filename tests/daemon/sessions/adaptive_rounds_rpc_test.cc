// Control.ListAdaptiveRounds on brdfd (docs/adaptive.md, "Every choice explained"): an adaptive
// session's rounds from the rig's store, the same records WatchSession carried, with what each
// was predicted to cost; brdfd and brdf-sim as processes.
#include <gtest/gtest.h>

#include <chrono>
#include <string>
#include <vector>

#include "google/protobuf/util/message_differencer.h"
#include "tests/daemon/sessions/rig_test.h"
#include "tests/support/plan_fixtures.h"

namespace brdf::testing {
namespace {

using namespace std::chrono_literals;

// examples/plans/adaptive.json made small (as adaptive_daemon_test.cc): three detector positions,
// a seed of 3 + 3 × 4, rounds of 6, to a budget of 27 readings.
const std::string kAdaptivePlan = R"({
  "name": "adaptive, rounds listed",
  "adaptive": {
    "target": {"expandedUncertainty": 0.001},
    "budget": {"maxReadings": 27},
    "region": {"thetaIMaxDeg": 80, "thetaOMaxDeg": 80},
    "method": "ADAPTIVE_JUDGE_OCTANT",
    "delta": {"start": 0, "stop": 22.5, "step": 11.25},
    "seed": {"retroReadings": 3, "readingsPerDelta": 4},
    "roundReadings": 6
  },
  "reference": {"perDetectorPosition": true},
  "measurement": {"integrationMs": 100, "averages": 1}
})";

class AdaptiveRoundsRpcTest : public SessionRigTest {
 protected:
  grpc::Status List(const std::string& id, v1::ListAdaptiveRoundsResponse* out,
                    const std::string& token = kAnalystToken) {
    v1::ListAdaptiveRoundsRequest request;
    request.set_session_id(id);
    return rig_.control().ListAdaptiveRounds(DaemonRig::Context(token).get(), request, out);
  }
};

TEST_F(AdaptiveRoundsRpcTest, TheStoredRoundsAreTheWatchedOnesWithTheirSpend) {
  Result<v1::Session> submitted = rig_.Submit(kAdaptivePlan);
  ASSERT_TRUE(submitted.ok()) << submitted.status().ToString();
  const std::string id = submitted->session_id();
  GrpcOperator& op = Watch(id);

  // While the seed is measured: no round yet.
  v1::ListAdaptiveRoundsResponse before;
  grpc::Status st = List(id, &before);
  ASSERT_TRUE(st.ok()) << st.error_message();
  EXPECT_EQ(before.rounds_size(), 0);

  const v1::Session done = rig_.WaitForState(id, v1::SESSION_STATE_COMPLETED, 90s);
  ASSERT_EQ(done.state(), v1::SESSION_STATE_COMPLETED) << done.DebugString() << rig_.log();
  op.Stop();
  std::vector<v1::AdaptiveRound> watched;
  for (const v1::SessionEvent& e : op.events()) {
    if (e.has_adaptive_round()) watched.push_back(e.adaptive_round());
  }
  ASSERT_GE(watched.size(), 2u);

  // An analyst may list them; they are the watched rounds, field for field.
  v1::ListAdaptiveRoundsResponse listed;
  st = List(id, &listed);
  ASSERT_TRUE(st.ok()) << st.error_message();
  ASSERT_EQ(listed.rounds_size(), static_cast<int>(watched.size()));
  const int seed_samples = static_cast<int>(submitted->summary().sample_readings());
  for (int i = 0; i < listed.rounds_size(); ++i) {
    const v1::AdaptiveRound& r = listed.rounds(i);
    EXPECT_TRUE(google::protobuf::util::MessageDifferencer::Equals(r, watched[i]))
        << "listed:\n"
        << r.DebugString() << "watched:\n"
        << watched[i].DebugString();
    EXPECT_EQ(r.round(), static_cast<std::uint32_t>(i + 1));
    EXPECT_GT(r.rig_s(), 0) << "round " << r.round();
    EXPECT_GT(r.spent_rig_s(), 0) << "round " << r.round();
    if (i == 0) {
      // The seed's spend: its readings and prompts, as the estimate summarised it at submission.
      EXPECT_EQ(static_cast<int>(r.readings_used()), seed_samples);
      EXPECT_EQ(r.spent_prompts(), submitted->summary().operator_interventions());
    } else {
      const v1::AdaptiveRound& prev = listed.rounds(i - 1);
      EXPECT_NEAR(r.spent_rig_s(), prev.spent_rig_s() + prev.rig_s(), 1e-6 * r.spent_rig_s());
      EXPECT_EQ(r.spent_prompts(), prev.spent_prompts() + prev.prompts());
      EXPECT_EQ(r.readings_used(), prev.readings_used() + prev.poses_size());
    }
  }
}

TEST_F(AdaptiveRoundsRpcTest, AnotherKindHasNoneAndABadIdIsNamed) {
  Result<v1::Session> fixed = rig_.Submit(plans::OnePose().Json(), /*start_now=*/false);
  ASSERT_TRUE(fixed.ok()) << fixed.status().ToString();
  v1::ListAdaptiveRoundsResponse none;
  grpc::Status st = List(fixed->session_id(), &none);
  ASSERT_TRUE(st.ok()) << st.error_message();
  EXPECT_EQ(none.rounds_size(), 0);

  v1::ListAdaptiveRoundsResponse out;
  st = List("999999", &out);
  EXPECT_EQ(st.error_code(), grpc::StatusCode::NOT_FOUND) << st.error_message();
  st = List("not-a-session", &out);
  EXPECT_EQ(st.error_code(), grpc::StatusCode::INVALID_ARGUMENT) << st.error_message();
  EXPECT_NE(st.error_message().find("session_id"), std::string::npos) << st.error_message();
}

}  // namespace
}  // namespace brdf::testing
