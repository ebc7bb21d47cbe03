// A full disk on the archive's server never pauses a recording. One simulated rig (brdf-sim and
// brdfd, as processes) ships to a real PostgreSQL whose directory is a small tmpfs; once the
// archive is caught up, a ballast file takes every free byte, so PostgreSQL's next write that
// needs space fails with "No space left on device", as on a real server whose disk filled up.
// The session records to the end with the archive refusing every batch; brdfd says the archive
// is unreachable and how far it trails; once space is freed it catches up, and the archive then
// holds exactly the rig's readings.
#include <gtest/gtest.h>

#include <chrono>
#include <thread>

#include "storage/session_store.h"
#include "tests/archive/archive_compare.h"
#include "tests/archive/archive_status.h"
#include "tests/support/daemon/test_rig.h"
#include "tests/support/pg/server.h"
#include "tests/support/plan_fixtures.h"

namespace brdf::testing {
namespace {

using namespace std::chrono_literals;

constexpr std::uint64_t kServerDisk = 160ull << 20;  // initdb's cluster needs about 40 MiB

class ArchiveFullDiskTest : public ::testing::Test {
 protected:
  void SetUp() override {
    if (std::string why = PgServer::Unavailable(); !why.empty()) GTEST_SKIP() << why;
    PgServer::Options options;
    options.disk_bytes = kServerDisk;
    Result<std::unique_ptr<PgServer>> pg = PgServer::Start(options);
    if (pg.status().code() == StatusCode::kFailedPrecondition) {
      GTEST_SKIP() << pg.status().ToString();
    }
    ASSERT_TRUE(pg.ok()) << pg.status().ToString();
    pg_ = std::move(*pg);
    rig_ = std::make_unique<DaemonRig>();
    Status sim = rig_->StartSim();
    ASSERT_TRUE(sim.ok()) << sim.ToString();
    const std::string credentials = rig_->dir().file("archive.conninfo").string();
    ASSERT_TRUE(PgServer::WriteCredentials(credentials, pg_->conninfo()).ok());
    Status daemon = rig_->StartDaemon(DaemonConfigToml(rig_->sim(), rig_->database()) +
                                      "[rig]\nname = \"rig-full\"\n[archive]\ncredentials = \"" +
                                      credentials + "\"\nretry_ms = 100\nbatch_readings = 5\n");
    ASSERT_TRUE(daemon.ok()) << daemon.ToString();
  }
  void TearDown() override {
    if (operator_ != nullptr) operator_->Stop();
    if (rig_ != nullptr && rig_->daemon() != nullptr) (void)rig_->StopDaemon();
    if (HasFailure() && rig_ != nullptr) std::cerr << "---- brdfd log ----\n" << rig_->log();
    if (HasFailure() && pg_ != nullptr) std::cerr << "---- postgres log ----\n" << pg_->log();
  }

  v1::ArchiveStatus Archive() { return RigArchiveStatus(*rig_); }
  bool WaitArchive(const std::function<bool(const v1::ArchiveStatus&)>& done) {
    return WaitRigArchiveStatus(*rig_, done);
  }

  std::unique_ptr<PgServer> pg_;
  std::unique_ptr<DaemonRig> rig_;
  std::unique_ptr<GrpcOperator> operator_;
};

TEST_F(ArchiveFullDiskTest, AFullArchiveDiskNeverPausesARecordingAndCatchesUpWhenFreed) {
  // The schema is in and the archive idle before its disk fills.
  ASSERT_TRUE(WaitArchive([](const v1::ArchiveStatus& s) {
    return s.state() == v1::ARCHIVE_STATE_CAUGHT_UP;
  })) << Archive().DebugString();
  ASSERT_TRUE(pg_->FillDisk().ok());

  Result<v1::Session> submitted = rig_->Submit(plans::SmallRotation());
  ASSERT_TRUE(submitted.ok()) << submitted.status().ToString();
  const std::string id = submitted->session_id();
  operator_ = std::make_unique<GrpcOperator>(*rig_, id);
  const v1::Session done = rig_->WaitForState(id, v1::SESSION_STATE_COMPLETED, 90s);
  ASSERT_EQ(done.state(), v1::SESSION_STATE_COMPLETED)
      << "recording stopped while the archive's disk was full: " << done.DebugString();
  for (const v1::SessionEvent& e : operator_->events()) {
    if (e.has_state_changed()) {
      EXPECT_NE(e.state_changed().to(), v1::SESSION_STATE_PAUSED) << e.DebugString();
    }
  }

  // Everything recorded waits on the rig, and brdfd says why.
  const std::size_t recorded = rig_->Readings(id)->size();
  ASSERT_GT(recorded, 0u);
  ASSERT_TRUE(WaitArchive([&](const v1::ArchiveStatus& s) {
    return s.state() == v1::ARCHIVE_STATE_UNREACHABLE && s.lag_readings() == recorded &&
           s.lag_seconds() > 0;
  })) << Archive().DebugString();
  EXPECT_NE(Archive().detail().find("No space left on device"), std::string::npos)
      << Archive().DebugString();

  ASSERT_TRUE(pg_->FreeDisk().ok());
  ASSERT_TRUE(WaitArchive([](const v1::ArchiveStatus& s) {
    return s.state() == v1::ARCHIVE_STATE_CAUGHT_UP && s.lag_readings() == 0;
  })) << Archive().DebugString();
  Result<int> code = rig_->StopDaemon();
  EXPECT_TRUE(code.ok() && *code == 0);
  auto store = storage::SessionStore::Open(rig_->database());
  ASSERT_TRUE(store.ok()) << store.status().ToString();
  storage::testing::ExpectArchiveHoldsExactly(pg_->conninfo(), **store, "rig-full");
}

}  // namespace
}  // namespace brdf::testing
