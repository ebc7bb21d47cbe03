// How soon rig status shows a stage that answers again (issue 21): the supervisor's stage back-off
// is capped by Rig::Options::stage_backoff_max ([stage] reconnect_max_ms), and asking for rig
// status or resuming (Rig::RetryStageNow) tries a disconnected stage at once. On the fake stage of
// tests/support/fakes/rig.h, whose Connect fails while it is unreachable.
#include <gtest/gtest.h>

#include <chrono>
#include <thread>

#include "tests/support/fakes/rig.h"

namespace brdf::testing {
namespace {

using namespace std::chrono_literals;
using daemon::DeviceConnection;
using Steady = std::chrono::steady_clock;

// Options whose general back-off grows quickly: after the fifth failure (1.7 s) the next attempt
// is 5 s away, and 30 s later on, without the stage's own cap.
daemon::Rig::Options GrowingBackoff(std::chrono::milliseconds stage_cap) {
  daemon::Rig::Options options = FastRigOptions();
  options.backoff_initial = 20ms;
  options.backoff_multiplier = 4;
  options.backoff_max = 30000ms;
  options.stage_backoff_max = stage_cap;
  return options;
}

DeviceConnection StageConnection(daemon::Rig& rig) {
  return rig.GetStatus().stage.connection;
}

// Waits (reading the status without asking for a retry) until the stage shows `want`.
bool WaitForStage(daemon::Rig& rig, DeviceConnection want, std::chrono::milliseconds limit) {
  const auto until = Steady::now() + limit;
  while (Steady::now() < until) {
    if (StageConnection(rig) == want) return true;
    std::this_thread::sleep_for(10ms);
  }
  return StageConnection(rig) == want;
}

// The stage is unreachable from the start, long enough for several failed attempts.
FakeRig StartUnreachable(daemon::Rig::Options options) {
  FakeRig fake = MakeFakeRig(SimRigDescription(), options);
  FakeFaults down;
  down.unreachable = true;
  fake.stage_faults->Set(down);
  fake.rig->Start();
  std::this_thread::sleep_for(2000ms);  // attempts at 0, 0.02, 0.1, 0.42, 1.7 s: all fail
  return fake;
}

TEST(RigReconnect, AStageThatAnswersAgainShowsWithinTheStageBackoffCap) {
  FakeRig fake = StartUnreachable(GrowingBackoff(400ms));
  ASSERT_EQ(StageConnection(*fake.rig), DeviceConnection::kDisconnected);
  ASSERT_GE(fake.rig->GetStatus().stage.failed_attempts, 4);  // the general back-off is at 5 s+

  fake.stage_faults->Set(FakeFaults{});
  const auto back = Steady::now();
  EXPECT_TRUE(WaitForStage(*fake.rig, DeviceConnection::kConnected, 2000ms))
      << "still " << daemon::DeviceConnectionName(StageConnection(*fake.rig));
  EXPECT_LT(Steady::now() - back, 1000ms);  // 400 ms cap + one attempt
  fake.rig->Stop();
}

TEST(RigReconnect, AskingForTheStageRetriesItAtOnce) {
  // The stage's cap as long as the general one: only RetryStageNow can bring it back soon.
  FakeRig fake = StartUnreachable(GrowingBackoff(30000ms));
  ASSERT_EQ(StageConnection(*fake.rig), DeviceConnection::kDisconnected);

  fake.stage_faults->Set(FakeFaults{});
  // Not asked: the back-off (seconds by now) keeps it disconnected.
  EXPECT_FALSE(WaitForStage(*fake.rig, DeviceConnection::kConnected, 500ms));
  // Asked (rig status, resume): tried now.
  const auto asked = Steady::now();
  fake.rig->RetryStageNow();
  EXPECT_TRUE(WaitForStage(*fake.rig, DeviceConnection::kConnected, 2000ms))
      << "still " << daemon::DeviceConnectionName(StageConnection(*fake.rig));
  EXPECT_LT(Steady::now() - asked, 500ms);
  fake.rig->Stop();
}

}  // namespace
}  // namespace brdf::testing
