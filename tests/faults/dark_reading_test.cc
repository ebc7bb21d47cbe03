// Dark readings are weak by design: the PR-650 reports quality 10 (weak light) or 18 (low light)
// with the shutter closed. The default policy fails 10 on a light reading (after adapting the
// integration), so a dark must be told apart: the executor marks its measurement as a dark
// (MeasurementSettings::dark) and the policy then accepts the low-light codes as they are. Checked
// on the policy, and end to end on brdfd + brdf-sim with the default policy (no override of 10).
#include <gtest/gtest.h>

#include <algorithm>
#include <chrono>

#include "drivers/pr650/quality_codes.h"
#include "tests/support/daemon/test_rig.h"
#include "tests/support/daemon/test_util.h"

namespace brdf::testing {
namespace {

using namespace std::chrono_literals;
using drivers::pr650::DecideQuality;
using drivers::pr650::MeasureLoopState;
using drivers::pr650::QualityDecision;
using drivers::pr650::QualityPolicy;
using Kind = QualityDecision::Kind;

TEST(DarkQualityPolicyTest, LowLightCodesAreAcceptedAsTheyAreOnADark) {
  const QualityPolicy policy = QualityPolicy::Defaults();
  for (int code : {10, 18}) {
    MeasureLoopState dark{200, false, 1, 4, /*low_light_expected=*/true};
    const QualityDecision d = DecideQuality(policy, code, dark);
    EXPECT_EQ(d.kind, Kind::kAccept) << code << ": " << d.note;
    EXPECT_NE(d.note.find("dark"), std::string::npos) << d.note;
    // At the integration limit and with adaptive integration too: never a failure.
    dark.integration_ms = 0;
    EXPECT_EQ(DecideQuality(policy, code, dark).kind, Kind::kAccept) << code;
  }
}

TEST(DarkQualityPolicyTest, OnALightReadingTheSameCodesFollowThePolicy) {
  const QualityPolicy policy = QualityPolicy::Defaults();
  const MeasureLoopState light{200, false, 1, 4, /*low_light_expected=*/false};
  const QualityDecision weak = DecideQuality(policy, 10, light);
  EXPECT_EQ(weak.kind, Kind::kRemeasure);
  EXPECT_EQ(weak.new_integration_ms, 400);
  EXPECT_EQ(DecideQuality(policy, 18, light).kind, Kind::kAcceptFlagged);
  // Adaptive integration cannot be doubled: a weak light reading fails.
  EXPECT_EQ(DecideQuality(policy, 10, MeasureLoopState{0, false, 1, 4, false}).kind, Kind::kFail);
}

TEST(DarkQualityPolicyTest, ADarkDoesNotExcuseOtherCodes) {
  const QualityPolicy policy = QualityPolicy::Defaults();
  const MeasureLoopState dark{200, false, 1, 4, /*low_light_expected=*/true};
  EXPECT_EQ(DecideQuality(policy, 19, dark).kind, Kind::kRemeasure);  // overload: halved
  EXPECT_EQ(DecideQuality(policy, 14, dark).kind, Kind::kFail);
  EXPECT_EQ(DecideQuality(policy, 42, dark).kind, Kind::kFail);
  EXPECT_EQ(DecideQuality(policy, 0, dark).kind, Kind::kAccept);
}

// A plan with darks runs to completion on brdfd's default quality policy: the simulator's darks
// earn quality 10, stored as measured, not flagged; the light readings are not 10.
TEST(DarkReadingDaemonTest, PlanWithDarksCompletesOnTheDefaultPolicy) {
  DaemonRig rig;
  ASSERT_TRUE(rig.StartSim().ok());
  std::string toml = DaemonConfigToml(rig.sim(), rig.database());
  const std::string override_10 = "[meter.quality]\n\"10\" = \"accept_and_flag\"\n";
  const auto at = toml.find(override_10);
  ASSERT_NE(at, std::string::npos) << "the daemon tests' configuration changed";
  toml.erase(at, override_10.size());
  Status started = rig.StartDaemon(toml);
  ASSERT_TRUE(started.ok()) << started.ToString();

  Result<v1::Session> s = rig.Submit(R"({
    "name": "darks",
    "poseList": {"poses": [{"alpha": 0, "beta": 10, "delta": 40},
                           {"alpha": 10, "beta": 40, "delta": 40}]},
    "reference": {"perDetectorPosition": true},
    "dark": {"withEachReference": true},
    "measurement": {"integrationMs": 200, "averages": 1},
    "retry": {"maxAttempts": 1, "backoffMs": 0}
  })");
  ASSERT_TRUE(s.ok()) << s.status().ToString();
  ASSERT_GT(s->summary().dark_readings(), 0u);
  GrpcOperator op(rig, s->session_id());
  const v1::Session done = rig.WaitFor(
      s->session_id(),
      [](const v1::Session& x) {
        return x.state() == v1::SESSION_STATE_PAUSED || IsTerminal(x.state());
      },
      60s);
  ASSERT_EQ(done.state(), v1::SESSION_STATE_COMPLETED) << done.DebugString() << "\n" << rig.log();
  Result<std::vector<v1::Reading>> readings = rig.Readings(s->session_id());
  ASSERT_TRUE(readings.ok());
  int darks = 0;
  for (const v1::Reading& r : *readings) {
    if (r.kind() == v1::READING_KIND_DARK) {
      ++darks;
      EXPECT_EQ(r.quality_code(), 10) << "the simulator's dark should be weak";
      EXPECT_FALSE(r.flagged());
    } else {
      EXPECT_NE(r.quality_code(), 10) << r.DebugString();
    }
  }
  EXPECT_EQ(darks, static_cast<int>(done.summary().dark_readings()));
  op.Stop();
  EXPECT_TRUE(op.errors().empty());
  Result<int> code = rig.StopDaemon();
  EXPECT_TRUE(code.ok() && *code == 0);
}

}  // namespace
}  // namespace brdf::testing
