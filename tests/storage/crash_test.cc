// Crash safety, the hard way: a child process runs a session the way the daemon does (resume,
// complete steps with their readings) and is SIGKILLed at a random moment, over and over. After
// every kill the parent reopens the file and checks that nothing was lost, duplicated or left
// half-written: every done measuring step has exactly one reading, no reading lacks its done step,
// done_steps matches, and the file passes integrity_check.
#include <gtest/gtest.h>
#include <signal.h>
#include <sys/wait.h>
#include <unistd.h>

#include <chrono>
#include <random>
#include <thread>

#include "storage/session_store.h"
#include "storage_test_util.h"

namespace brdf::storage {
namespace {

using testing::KindOfStep;
using testing::MakeNewSession;
using testing::MakeReading;
using testing::MakeSteps;
using testing::ReadingKindOfStep;
using testing::TempDir;

constexpr int kSteps = 2000;  // more than a child can finish before it is killed

// The child: what the daemon's executor does with storage after a restart. Returns only on error
// (exit code says which); signals the parent through `ready_fd` once it has committed a step.
[[noreturn]] void RunSessionUntilKilled(const std::string& path, std::int64_t session,
                                        int ready_fd) {
  auto store = SessionStore::Open(path);
  if (!store.ok()) _exit(10);
  if (!(*store)->RecoverInterruptedSessions().ok()) _exit(11);
  if (!(*store)->SetSessionState(session, SessionState::kRunning, "resumed by test").ok()) {
    _exit(12);
  }
  // The reference that samples are divided by: the latest reference reading so far.
  std::optional<std::int64_t> reference;
  Status walk = (*store)->ForEachReading(session, [&](const ReadingRecord& r) {
    if (r.kind == ReadingKind::kReference) reference = r.id;
    return Status::Ok();
  });
  if (!walk.ok()) _exit(13);
  bool signalled = false;
  while (true) {
    auto next = (*store)->FirstUnfinishedStep(session);
    if (!next.ok()) _exit(14);
    if (!next->has_value()) _exit(0);  // finished before the kill
    const int i = **next;
    if (KindOfStep(i) == StepKind::kMove) {
      if (!(*store)->CompleteStep(session, i).ok()) _exit(15);
    } else {
      ReadingRecord r = MakeReading(i, ReadingKindOfStep(i));
      if (r.kind == ReadingKind::kSample) r.reference_reading_id = reference;
      auto id = (*store)->CompleteStepWithReading(session, i, r);
      if (!id.ok()) _exit(16);
      if (r.kind == ReadingKind::kReference) reference = *id;
    }
    if (!signalled) {
      const char byte = 1;
      if (write(ready_fd, &byte, 1) != 1) _exit(17);
      signalled = true;
    }
  }
}

TEST(CrashSafetyTest, SigkilledWriterNeverLeavesAPartialOrDuplicateStep) {
  TempDir dir;
  const std::string path = dir.File("brdfd.db");
  std::int64_t session = 0;
  {
    auto store = SessionStore::Open(path);
    ASSERT_TRUE(store.ok()) << store.status().ToString();
    auto id = (*store)->CreateSession(MakeNewSession(), MakeSteps(kSteps));
    ASSERT_TRUE(id.ok()) << id.status().ToString();
    session = *id;
  }  // no connection may cross fork()

  const unsigned seed = std::random_device{}();
  SCOPED_TRACE("seed " + std::to_string(seed));
  std::mt19937 rng(seed);
  std::uniform_int_distribution<int> delay_us(0, 80000);

  int previous_done = 0;
  int kills = 0;
  for (int round = 0; round < 12; ++round) {
    SCOPED_TRACE("round " + std::to_string(round));
    int fds[2];
    ASSERT_EQ(pipe(fds), 0);
    const pid_t pid = fork();
    ASSERT_GE(pid, 0);
    if (pid == 0) {
      close(fds[0]);
      RunSessionUntilKilled(path, session, fds[1]);
    }
    close(fds[1]);
    char byte = 0;
    const bool started = read(fds[0], &byte, 1) == 1;  // 0 bytes: the child exited early
    close(fds[0]);
    if (started) {
      std::this_thread::sleep_for(std::chrono::microseconds(delay_us(rng)));
      kill(pid, SIGKILL);
    }
    int status = 0;
    ASSERT_EQ(waitpid(pid, &status, 0), pid);
    if (WIFSIGNALED(status)) {
      ++kills;
    } else {
      ASSERT_TRUE(WIFEXITED(status));
      ASSERT_EQ(WEXITSTATUS(status), 0) << "the child failed (see its exit codes)";
    }

    auto store = SessionStore::Open(path);
    ASSERT_TRUE(store.ok()) << store.status().ToString();
    auto report = (*store)->CheckSession(session);
    ASSERT_TRUE(report.ok()) << report.status().ToString();
    ASSERT_TRUE(report->ok()) << report->Summary();
    EXPECT_EQ(report->integrity_check, "ok");
    auto steps = (*store)->GetSteps(session);
    ASSERT_TRUE(steps.ok());
    int measuring_done = 0;
    for (const StepRecord& s : *steps) {
      if (s.state == StepState::kDone && s.kind != StepKind::kMove) ++measuring_done;
    }
    EXPECT_EQ(report->readings, measuring_done) << "readings == done measuring steps";
    EXPECT_GE(report->done_steps_recorded, previous_done) << "a committed step was lost";
    previous_done = report->done_steps_recorded;
    // Every stored reading is the one its step produced.
    ASSERT_TRUE((*store)
                    ->ForEachReading(session,
                                     [](const ReadingRecord& r) {
                                       EXPECT_EQ(r.spectrum,
                                                 MakeReading(r.step_index, r.kind).spectrum);
                                       return Status::Ok();
                                     })
                    .ok());
    if (previous_done == kSteps) break;
  }
  EXPECT_GT(kills, 0);
  EXPECT_GT(previous_done, 0);
  std::printf("crash campaign: %d kills, %d of %d steps done\n", kills, previous_done, kSteps);
}

// Killing the daemon while it stores a new plan leaves either the whole session or nothing.
TEST(CrashSafetyTest, SigkilledSessionCreationIsAllOrNothing) {
  TempDir dir;
  const std::string path = dir.File("brdfd.db");
  { ASSERT_TRUE(SessionStore::Open(path).ok()); }
  const unsigned seed = std::random_device{}();
  SCOPED_TRACE("seed " + std::to_string(seed));
  std::mt19937 rng(seed);
  std::uniform_int_distribution<int> delay_us(0, 60000);
  constexpr int kPlanSteps = 300;
  int kills = 0;
  for (int round = 0; round < 8; ++round) {
    int fds[2];
    ASSERT_EQ(pipe(fds), 0);
    const pid_t pid = fork();
    ASSERT_GE(pid, 0);
    if (pid == 0) {
      close(fds[0]);
      auto store = SessionStore::Open(path);
      if (!store.ok()) _exit(10);
      const char byte = 1;
      if (write(fds[1], &byte, 1) != 1) _exit(11);
      for (int n = 0; n < 1000; ++n) {
        if (!(*store)->CreateSession(MakeNewSession(), MakeSteps(kPlanSteps)).ok()) _exit(12);
      }
      _exit(0);
    }
    close(fds[1]);
    char byte = 0;
    const bool started = read(fds[0], &byte, 1) == 1;
    close(fds[0]);
    if (started) {
      std::this_thread::sleep_for(std::chrono::microseconds(delay_us(rng)));
      kill(pid, SIGKILL);
    }
    int status = 0;
    ASSERT_EQ(waitpid(pid, &status, 0), pid);
    if (WIFSIGNALED(status)) ++kills;
  }
  EXPECT_GT(kills, 0);
  auto store = SessionStore::Open(path);
  ASSERT_TRUE(store.ok());
  auto sessions = (*store)->ListSessions();
  ASSERT_TRUE(sessions.ok());
  for (const SessionRecord& s : *sessions) {
    auto report = (*store)->CheckSession(s.id);
    ASSERT_TRUE(report.ok());
    EXPECT_TRUE(report->ok()) << report->Summary();
    EXPECT_EQ(report->steps_present, kPlanSteps);
  }
  std::printf("creation campaign: %d kills, %zu whole sessions\n", kills, sessions->size());
}

}  // namespace
}  // namespace brdf::storage
