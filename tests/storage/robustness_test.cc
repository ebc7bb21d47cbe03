// The local system failing under the store: a database the OS will not let us write, a full disk,
// and readers working while the writer writes.
#include <gmock/gmock.h>
#include <gtest/gtest.h>
#include <sys/stat.h>
#include <unistd.h>

#include <atomic>
#include <filesystem>
#include <thread>

#include "storage/session_store.h"
#include "storage_test_util.h"

namespace brdf::storage {
namespace {

using ::testing::HasSubstr;
using testing::KindOfStep;
using testing::MakeNewSession;
using testing::MakeReading;
using testing::MakeSteps;
using testing::ReadingKindOfStep;
using testing::RunUnprivileged;
using testing::TempDir;

// A brdfd database with one session, then closed (no -wal/-shm left behind).
std::int64_t MakeDatabase(const std::string& path) {
  auto store = SessionStore::Open(path);
  EXPECT_TRUE(store.ok()) << store.status().ToString();
  auto id = (*store)->CreateSession(MakeNewSession(), MakeSteps(5));
  EXPECT_TRUE(id.ok());
  return *id;
}

TEST(ReadOnlyTest, UnwritableFileIsAnIoErrorAtOpenNamingPermissions) {
  TempDir dir;
  const std::string path = dir.File("brdfd.db");
  MakeDatabase(path);
  ASSERT_EQ(chmod(dir.path().c_str(), 0755), 0);
  ASSERT_EQ(chmod(path.c_str(), 0444), 0);
  auto child = RunUnprivileged([&](std::string& out) {
    auto store = SessionStore::Open(path);
    if (store.ok()) return 1;
    out = store.status().ToString();
    return store.status().code() == StatusCode::kIoError ? 0 : 2;
  });
  EXPECT_EQ(child.exit_code, 0) << child.output;
  EXPECT_THAT(child.output, HasSubstr("io_error"));
  EXPECT_THAT(child.output, HasSubstr(path));
  EXPECT_THAT(child.output, HasSubstr("SQLITE_READONLY"));
  EXPECT_THAT(child.output, HasSubstr("check the permissions of the file AND of its directory"));
}

TEST(ReadOnlyTest, UnwritableDirectoryIsAnIoErrorNamingTheDirectory) {
  TempDir dir;
  const std::string sub = dir.File("data");
  ASSERT_TRUE(std::filesystem::create_directory(sub));
  const std::string path = sub + "/brdfd.db";
  MakeDatabase(path);
  ASSERT_EQ(chmod(dir.path().c_str(), 0755), 0);
  // The file is writable by everyone; only the directory (where -wal and -shm go) is not.
  ASSERT_EQ(chmod(path.c_str(), 0666), 0);
  ASSERT_EQ(chmod(sub.c_str(), 0555), 0);
  auto child = RunUnprivileged([&](std::string& out) {
    auto store = SessionStore::Open(path);
    if (store.ok()) {
      // Some platforms only notice at the first write.
      auto id = (*store)->CreateSession(MakeNewSession(), MakeSteps(2));
      if (id.ok()) return 1;
      out = id.status().ToString();
      return id.status().code() == StatusCode::kIoError ? 0 : 2;
    }
    out = store.status().ToString();
    return store.status().code() == StatusCode::kIoError ? 0 : 2;
  });
  ASSERT_EQ(chmod(sub.c_str(), 0755), 0);
  EXPECT_EQ(child.exit_code, 0) << child.output;
  EXPECT_THAT(child.output, HasSubstr("io_error"));
  EXPECT_THAT(child.output, HasSubstr(sub));
  EXPECT_THAT(child.output, HasSubstr("-wal"));
}

TEST(DiskFullTest, AFullDiskRefusesTheWriteKeepsEverythingCommittedAndRecovers) {
  TempDir dir;
  const std::string path = dir.File("brdfd.db");
  std::int64_t session = 0;
  int committed = 0;
  int failed_step = -1;
  {
    SessionStore::Options small;
    // Room for the schema (v3: 13 tables and indexes), the session and its 400 steps, and some
    // readings: the limit is reached while recording.
    small.max_database_bytes = 128 * 1024;
    auto store = SessionStore::Open(path, small);
    ASSERT_TRUE(store.ok()) << store.status().ToString();
    auto id = (*store)->CreateSession(MakeNewSession(), MakeSteps(400));
    ASSERT_TRUE(id.ok()) << id.status().ToString();
    session = *id;
    ASSERT_TRUE((*store)->SetSessionState(session, SessionState::kRunning, "").ok());
    Status last;
    for (int i = 0; i < 400; ++i) {
      if (KindOfStep(i) == StepKind::kMove) {
        last = (*store)->CompleteStep(session, i);
      } else {
        last = (*store)
                   ->CompleteStepWithReading(session, i, MakeReading(i, ReadingKindOfStep(i)))
                   .status();
      }
      if (!last.ok()) {
        failed_step = i;
        break;
      }
      ++committed;
    }
    ASSERT_GE(failed_step, 0) << "the size limit was never reached";
    EXPECT_EQ(last.code(), StatusCode::kIoError) << last.ToString();
    EXPECT_THAT(last.message(), HasSubstr("step " + std::to_string(failed_step)));
    EXPECT_THAT(last.message(), HasSubstr("SQLITE_FULL"));
    EXPECT_THAT(last.message(), HasSubstr("free space"));
    // Nothing partial; reads still work; the step is still to do.
    auto report = (*store)->CheckSession(session);
    ASSERT_TRUE(report.ok()) << report.status().ToString();
    EXPECT_TRUE(report->ok()) << report->Summary();
    EXPECT_EQ(report->done_steps_recorded, committed);
    EXPECT_EQ(**(*store)->FirstUnfinishedStep(session), failed_step);
  }
  // Space freed (no limit): the same step now goes through.
  auto store = SessionStore::Open(path);
  ASSERT_TRUE(store.ok());
  const Status retry =
      KindOfStep(failed_step) == StepKind::kMove
          ? (*store)->CompleteStep(session, failed_step)
          : (*store)
                ->CompleteStepWithReading(session, failed_step,
                                          MakeReading(failed_step, ReadingKindOfStep(failed_step)))
                .status();
  ASSERT_TRUE(retry.ok()) << retry.ToString();
  auto report = (*store)->CheckSession(session);
  ASSERT_TRUE(report.ok());
  EXPECT_TRUE(report->ok()) << report->Summary();
  EXPECT_EQ(report->done_steps_recorded, committed + 1);
}

TEST(ConcurrencyTest, ReadersSeeConsistentSnapshotsWhileTheWriterWrites) {
  TempDir dir;
  const std::string path = dir.File("brdfd.db");
  SessionStore::Options options;
  options.busy_timeout = std::chrono::milliseconds(2000);
  auto opened = SessionStore::Open(path, options);
  ASSERT_TRUE(opened.ok());
  SessionStore& store = **opened;
  constexpr int kSteps = 240;
  auto id = store.CreateSession(MakeNewSession(), MakeSteps(kSteps));
  ASSERT_TRUE(id.ok());
  const std::int64_t session = *id;
  ASSERT_TRUE(store.SetSessionState(session, SessionState::kRunning, "").ok());

  std::atomic<bool> done{false};
  std::atomic<int> checks{0};
  std::atomic<int> failures{0};
  auto reader = [&] {
    int last_done = 0;
    int last_count = 0;
    while (!done.load()) {
      auto report = store.CheckSession(session);
      if (!report.ok() || !report->ok()) {
        ++failures;
        ADD_FAILURE() << (report.ok() ? report->Summary() : report.status().ToString());
        return;
      }
      // Progress never goes backwards, and every reading read back is intact.
      EXPECT_GE(report->done_steps_recorded, last_done);
      last_done = report->done_steps_recorded;
      int count = 0;
      Status walk = store.ForEachReading(session, [&](const ReadingRecord& r) {
        ++count;
        EXPECT_EQ(r.spectrum, MakeReading(r.step_index, r.kind).spectrum);
        return Status::Ok();
      });
      EXPECT_TRUE(walk.ok()) << walk.ToString();
      EXPECT_GE(count, last_count);
      last_count = count;
      ++checks;
    }
  };
  std::vector<std::thread> readers;
  for (int i = 0; i < 3; ++i) readers.emplace_back(reader);

  for (int i = 0; i < kSteps && failures.load() == 0; ++i) {
    Status s = KindOfStep(i) == StepKind::kMove
                   ? store.CompleteStep(session, i)
                   : store.CompleteStepWithReading(session, i, MakeReading(i, ReadingKindOfStep(i)))
                         .status();
    ASSERT_TRUE(s.ok()) << "step " << i << ": " << s.ToString();
  }
  done = true;
  for (std::thread& t : readers) t.join();
  EXPECT_EQ(failures.load(), 0);
  EXPECT_GT(checks.load(), 0);
  EXPECT_EQ(store.GetSession(session)->done_steps, kSteps);
}

TEST(ConcurrencyTest, AnOpenReadTransactionNeitherBlocksTheWriterNorSeesItHalfWay) {
  TempDir dir;
  const std::string path = dir.File("brdfd.db");
  SessionStore::Options options;
  options.busy_timeout = std::chrono::milliseconds(100);  // a blocked writer would fail fast
  auto store = SessionStore::Open(path, options);
  ASSERT_TRUE(store.ok());
  auto id = (*store)->CreateSession(MakeNewSession(), MakeSteps(30));
  ASSERT_TRUE(id.ok());
  ASSERT_TRUE((*store)->SetSessionState(*id, SessionState::kRunning, "").ok());

  // Another process's reader (a backup, a sqlite3 shell) holding a snapshot.
  auto other = Database::Open(path);
  ASSERT_TRUE(other.ok());
  auto tx = Transaction::BeginRead(**other);
  ASSERT_TRUE(tx.ok());
  EXPECT_EQ(*(*other)->QueryInt64("SELECT count(*) FROM readings"), 0);

  for (int i = 1; i < 30; ++i) {
    if (KindOfStep(i) == StepKind::kMove) continue;
    auto r = (*store)->CompleteStepWithReading(*id, i, MakeReading(i, ReadingKindOfStep(i)));
    ASSERT_TRUE(r.ok()) << r.status().ToString();
  }
  EXPECT_EQ(*(*other)->QueryInt64("SELECT count(*) FROM readings"), 0) << "its snapshot holds";
  ASSERT_TRUE(tx->Commit().ok());
  EXPECT_EQ(*(*other)->QueryInt64("SELECT count(*) FROM readings"), 27);
  EXPECT_EQ(*(*store)->CountReadings(*id), 27);
}

}  // namespace
}  // namespace brdf::storage
