// kill -9 in the middle of a session: a child process runs the engine (store, rig, manager, an
// operator answering prompts) on the fake meter and stage and is killed with SIGKILL once part of
// the plan is done. A new manager on the same database recovers the session as paused at its first
// unfinished step; resuming completes it, and every step is in the database exactly once.
#include <gtest/gtest.h>
#include <poll.h>
#include <signal.h>
#include <sys/wait.h>
#include <unistd.h>

#include <chrono>
#include <cstring>
#include <thread>

#include "core/plan/plan_json.h"
#include "daemon/engine/session_manager.h"
#include "storage/session_store.h"
#include "tests/engine/engine_test_rig.h"
#include "tests/support/plan_fixtures.h"

namespace brdf::testing {
namespace {

using namespace std::chrono_literals;

const std::string kPlan = PlanFixture("to be interrupted")
                              .SampleRotation({20, 40, 20}, {0, 20, 20}, 45)
                              .Measurement(1000, 1)
                              .Retry(3, 0);

// The child: runs the session until it is killed. Writes the session id to `fd`.
[[noreturn]] void RunChild(const std::string& db, int fd) {
  auto store = storage::SessionStore::Open(db);
  if (!store.ok()) ::_exit(10);
  FakeRig fake = MakeFakeRig();
  daemon::SessionManager manager(std::move(*store), fake.rig, ManagerOptions());
  auto plan = plan::ParsePlanJson(kPlan);
  if (!plan.ok()) ::_exit(13);
  auto session = manager.SubmitPlan(*plan, kTestOperator, /*start_now=*/true);
  if (!session.ok()) ::_exit(14);
  const daemon::SessionId id = IdOf(*session);
  if (::write(fd, &id, sizeof id) != static_cast<ssize_t>(sizeof id)) ::_exit(15);
  Operator op(manager, *fake.bench, id);
  for (;;) ::pause();  // until SIGKILL
}

TEST(RestartRecoveryTest, KilledMidSessionComesBackPausedAndResumesWithoutLossOrDuplicate) {
  TempDir dir("brdf-engine-restart");
  const std::string db = dir.file("brdfd.db").string();

  int fds[2];
  ASSERT_EQ(::pipe(fds), 0) << std::strerror(errno);
  // No thread of ours runs yet, so the child may do anything after fork.
  const pid_t child = ::fork();
  ASSERT_GE(child, 0) << std::strerror(errno);
  if (child == 0) {
    ::close(fds[0]);
    RunChild(db, fds[1]);
  }
  ::close(fds[1]);
  struct ChildGuard {
    pid_t pid;
    ~ChildGuard() {
      if (pid > 0) {
        ::kill(pid, SIGKILL);
        ::waitpid(pid, nullptr, 0);
      }
    }
  } guard{child};

  pollfd pfd{fds[0], POLLIN, 0};
  ASSERT_EQ(::poll(&pfd, 1, 15000), 1) << "the child did not start its session";
  daemon::SessionId id = 0;
  ASSERT_EQ(::read(fds[0], &id, sizeof id), static_cast<ssize_t>(sizeof id));
  ::close(fds[0]);
  ASSERT_GT(id, 0);

  auto opened = storage::SessionStore::Open(db);
  ASSERT_TRUE(opened.ok()) << opened.status().ToString();
  std::shared_ptr<storage::SessionStore> store = std::move(*opened);
  // Let it get about half-way, then kill it without warning.
  int total = 0, done = 0;
  const auto until = std::chrono::steady_clock::now() + 20s;
  while (std::chrono::steady_clock::now() < until) {
    auto s = store->GetSession(id);
    ASSERT_TRUE(s.ok()) << s.status().ToString();
    total = s->total_steps;
    done = s->done_steps;
    if (done * 2 >= total) break;
    std::this_thread::sleep_for(5ms);
  }
  ASSERT_GT(done, 0);
  ASSERT_LT(done, total) << "the session ended before it could be killed";
  ASSERT_EQ(::kill(child, SIGKILL), 0);
  int wstatus = 0;
  ASSERT_EQ(::waitpid(child, &wstatus, 0), child);
  guard.pid = -1;
  ASSERT_TRUE(WIFSIGNALED(wstatus));

  // What the dead daemon left: whole steps only.
  auto before = store->CheckSession(id);
  ASSERT_TRUE(before.ok());
  EXPECT_TRUE(before->ok()) << before->Summary();
  auto steps_before = store->GetSteps(id);
  ASSERT_TRUE(steps_before.ok());
  int done_readings = 0;
  for (const auto& st : *steps_before) {
    const bool reading = st.kind == storage::StepKind::kReference ||
                         st.kind == storage::StepKind::kDark ||
                         st.kind == storage::StepKind::kSample;
    if (reading && st.state == storage::StepState::kDone) ++done_readings;
  }
  EXPECT_EQ(before->readings, done_readings);

  // A new daemon on the same database.
  FakeRig fake = MakeFakeRig();
  daemon::SessionManager manager(store, fake.rig, ManagerOptions());
  auto recovered = manager.Recover();
  ASSERT_TRUE(recovered.ok()) << recovered.status().ToString();
  EXPECT_EQ(*recovered, std::vector<daemon::SessionId>{id});
  auto paused = manager.GetSession(id);
  ASSERT_TRUE(paused.ok());
  EXPECT_EQ(paused->state(), v1::SESSION_STATE_PAUSED);
  auto first = store->FirstUnfinishedStep(id);
  ASSERT_TRUE(first.ok() && first->has_value());
  EXPECT_EQ(paused->current_step(), **first);
  EXPECT_EQ(manager.GetRigStatus().active_session_id(), std::to_string(id));
  auto record = store->GetSession(id);
  ASSERT_TRUE(record.ok());
  EXPECT_EQ(record->state_reason, storage::kRecoveredReason);

  Operator op(manager, *fake.bench, id);
  auto resumed = manager.Resume(id, kTestOperator);
  ASSERT_TRUE(resumed.ok()) << resumed.status().ToString();
  const v1::Session finished = WaitForSession(manager, id, [](const v1::Session& s) {
    return s.state() == v1::SESSION_STATE_COMPLETED || s.state() == v1::SESSION_STATE_PAUSED ||
           s.state() == v1::SESSION_STATE_FAILED;
  });
  ASSERT_EQ(finished.state(), v1::SESSION_STATE_COMPLETED)
      << (finished.has_last_fault() ? finished.last_fault().reason() : "");
  op.Stop();
  for (const std::string& e : op.errors()) ADD_FAILURE() << "operator: " << e;

  auto after = store->CheckSession(id);
  ASSERT_TRUE(after.ok());
  EXPECT_TRUE(after->ok()) << after->Summary();
  EXPECT_EQ(after->steps_present, after->total_steps);
  EXPECT_EQ(after->steps_done, after->total_steps);
  EXPECT_EQ(after->readings, static_cast<int>(finished.summary().sample_readings() +
                                              finished.summary().reference_readings() +
                                              finished.summary().dark_readings()));
  manager.Shutdown(5s);
}

}  // namespace
}  // namespace brdf::testing
