// Two simulated rigs (two brdf-sim, two brdfd, as processes) record at the same time into one real
// PostgreSQL. Faults come from outside: PostgreSQL is stopped in the middle of the sessions and
// started again; a brdfd is SIGKILLed while it ships. Recording never pauses for the archive, and
// in the end the archive is compared with each rig's SQLite file reading by reading.
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <chrono>
#include <thread>

#include "storage/session_store.h"
#include "tests/archive/archive_compare.h"
#include "tests/archive/archive_status.h"
#include "tests/support/daemon/test_rig.h"
#include "tests/support/pg/server_fixture.h"
#include "tests/support/plan_fixtures.h"

namespace brdf::testing {
namespace {

using namespace std::chrono_literals;

class ArchiveRigTest : public PgServerTest {
 protected:
  void SetUp() override {
    PgServerTest::SetUp();
    if (!PgReady()) return;
    for (int i = 0; i < 2; ++i) {
      rigs_[i] = std::make_unique<DaemonRig>();
      Status sim = rigs_[i]->StartSim();
      ASSERT_TRUE(sim.ok()) << sim.ToString();
      Result<std::string> cred = PgServer::WriteCredentials(
          rigs_[i]->dir().file("archive.conninfo").string(), pg_->conninfo());
      ASSERT_TRUE(cred.ok());
      Status daemon = rigs_[i]->StartDaemon(Toml(i));
      ASSERT_TRUE(daemon.ok()) << daemon.ToString();
    }
  }
  void TearDown() override {
    for (auto& op : operators_) op->Stop();
    operators_.clear();
    for (auto& rig : rigs_) {
      if (rig != nullptr && rig->daemon() != nullptr) (void)rig->StopDaemon();
      if (rig != nullptr && HasFailure()) std::cerr << "---- brdfd log ----\n" << rig->log();
    }
    if (HasFailure() && pg_ != nullptr) std::cerr << "---- postgres log ----\n" << pg_->log();
  }

  std::string Name(int i) const { return i == 0 ? "rig-a" : "rig-b"; }
  std::string Toml(int i, int batch = 20) const {
    return DaemonConfigToml(rigs_[i]->sim(), rigs_[i]->database()) + "[rig]\nname = \"" + Name(i) +
           "\"\n[archive]\ncredentials = \"" + rigs_[i]->dir().file("archive.conninfo").string() +
           "\"\nretry_ms = 100\nbatch_readings = " + std::to_string(batch) + "\n";
  }
  v1::ArchiveStatus Archive(int i) { return RigArchiveStatus(*rigs_[i]); }
  bool WaitArchive(int i, const std::function<bool(const v1::ArchiveStatus&)>& done,
                   std::chrono::seconds timeout = 30s) {
    return WaitRigArchiveStatus(*rigs_[i], done, timeout);
  }
  std::string Submit(int i) {
    Result<v1::Session> s = rigs_[i]->Submit(plans::SmallRotation());
    EXPECT_TRUE(s.ok()) << s.status().ToString();
    if (!s.ok()) return "";
    operators_.push_back(std::make_unique<GrpcOperator>(*rigs_[i], s->session_id()));
    return s->session_id();
  }
  // Stops both daemons and compares each rig's database with the archive.
  void StopAndCompare() {
    for (int i = 0; i < 2; ++i) {
      Result<int> code = rigs_[i]->StopDaemon();
      EXPECT_TRUE(code.ok() && *code == 0);
      auto store = storage::SessionStore::Open(rigs_[i]->database());
      ASSERT_TRUE(store.ok()) << store.status().ToString();
      storage::testing::ExpectArchiveHoldsExactly(pg_->conninfo(), **store, Name(i));
    }
  }

  std::unique_ptr<DaemonRig> rigs_[2];
  std::vector<std::unique_ptr<GrpcOperator>> operators_;
};

TEST_F(ArchiveRigTest, TwoRigsRecordIntoOneArchiveThroughAPostgresRestart) {
  const std::string a = Submit(0);
  const std::string b = Submit(1);
  for (int i = 0; i < 2; ++i) {
    rigs_[i]->WaitFor(i == 0 ? a : b,
                      [](const v1::Session& s) { return s.progress().done_samples() >= 2; });
  }
  ASSERT_TRUE(pg_->Stop().ok());
  // The rigs go on recording with the archive away, and say so.
  const std::uint32_t before = rigs_[0]->Get(a)->progress().done_samples();
  ASSERT_TRUE(WaitArchive(0, [](const v1::ArchiveStatus& s) {
    return s.state() == v1::ARCHIVE_STATE_UNREACHABLE && s.lag_readings() > 0 &&
           s.lag_seconds() > 0;
  })) << Archive(0).DebugString();
  const v1::Session during = rigs_[0]->WaitFor(
      a, [&](const v1::Session& s) { return s.progress().done_samples() >= before + 3; });
  EXPECT_GE(during.progress().done_samples(), before + 3) << "recording paused for the archive";
  EXPECT_EQ(during.state(), v1::SESSION_STATE_RUNNING);
  ASSERT_TRUE(pg_->Restart().ok());
  for (int i = 0; i < 2; ++i) {
    const v1::Session done =
        rigs_[i]->WaitForState(i == 0 ? a : b, v1::SESSION_STATE_COMPLETED, 90s);
    ASSERT_EQ(done.state(), v1::SESSION_STATE_COMPLETED) << done.DebugString();
    ASSERT_TRUE(WaitArchive(i, [](const v1::ArchiveStatus& s) {
      return s.state() == v1::ARCHIVE_STATE_CAUGHT_UP && s.lag_readings() == 0;
    })) << Archive(i).DebugString();
  }
  StopAndCompare();
  EXPECT_EQ(*pg_->Psql("SELECT count(DISTINCT rig) FROM sessions"), "2");
}

TEST_F(ArchiveRigTest, BrdfdKilledWhileShippingLeavesEachReadingOnceInTheArchive) {
  // A backlog, shipped a reading per transaction, and a SIGKILL in the middle of it.
  ASSERT_TRUE(rigs_[0]->StopDaemon().ok());
  ASSERT_TRUE(rigs_[0]->StartDaemon(Toml(0, /*batch=*/1)).ok());
  ASSERT_TRUE(pg_->Stop().ok());
  const std::string a = Submit(0);
  const std::string b = Submit(1);
  const v1::Session done_a = rigs_[0]->WaitForState(a, v1::SESSION_STATE_COMPLETED, 90s);
  ASSERT_EQ(done_a.state(), v1::SESSION_STATE_COMPLETED);
  ASSERT_TRUE(pg_->Restart().ok());
  v1::ArchiveStatus at_kill;
  const auto deadline = std::chrono::steady_clock::now() + 30s;
  while (std::chrono::steady_clock::now() < deadline) {
    at_kill = Archive(0);
    if (at_kill.shipped_readings() > 0) break;
    std::this_thread::sleep_for(2ms);
  }
  ASSERT_GT(at_kill.shipped_readings(), 0u) << at_kill.DebugString();
  EXPECT_GT(at_kill.lag_readings(), 0u)
      << "shipping finished before the kill: " << at_kill.DebugString();
  operators_.front()->Stop();
  rigs_[0]->KillDaemon();
  std::cerr << "killed with " << at_kill.shipped_readings() << " shipped, "
            << at_kill.lag_readings() << " behind\n";
  ASSERT_TRUE(rigs_[0]->StartDaemon(Toml(0)).ok());
  for (int i = 0; i < 2; ++i) {
    const v1::Session done =
        rigs_[i]->WaitForState(i == 0 ? a : b, v1::SESSION_STATE_COMPLETED, 90s);
    ASSERT_EQ(done.state(), v1::SESSION_STATE_COMPLETED) << done.DebugString();
    ASSERT_TRUE(WaitArchive(i, [](const v1::ArchiveStatus& s) {
      return s.state() == v1::ARCHIVE_STATE_CAUGHT_UP && s.lag_readings() == 0;
    })) << Archive(i).DebugString();
  }
  StopAndCompare();
}

TEST_F(ArchiveRigTest, WrongPasswordNeverPausesARecording) {
  ASSERT_TRUE(rigs_[0]->StopDaemon().ok());
  ASSERT_TRUE(PgServer::WriteCredentials(rigs_[0]->dir().file("archive.conninfo").string(),
                                         pg_->conninfo_with_password("not-it-0123456789"))
                  .ok());
  ASSERT_TRUE(rigs_[0]->StartDaemon(Toml(0)).ok());
  const std::string a = Submit(0);
  const v1::Session done = rigs_[0]->WaitForState(a, v1::SESSION_STATE_COMPLETED, 90s);
  ASSERT_EQ(done.state(), v1::SESSION_STATE_COMPLETED) << done.DebugString();
  const v1::ArchiveStatus refused = Archive(0);
  EXPECT_EQ(refused.state(), v1::ARCHIVE_STATE_REFUSED) << refused.DebugString();
  EXPECT_EQ(refused.lag_readings(), static_cast<std::uint64_t>(rigs_[0]->Readings(a)->size()));
  EXPECT_EQ(rigs_[0]->log().find("not-it-0123456789"), std::string::npos)
      << "the password is in brdfd's log";
}

}  // namespace
}  // namespace brdf::testing
