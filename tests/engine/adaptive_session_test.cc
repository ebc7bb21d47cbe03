// Adaptive sessions on the engine (docs/adaptive.md, "Rounds as steps"): the seed design, then
// rounds chosen from the committed readings, each stored with its steps before it is measured,
// until a budget stops the session. The uncertainty model is the planner tests' stand-in
// (tests/adaptive/kernel_model.h), injected through SessionManager::Options. kill -9 runs as in
// restart_recovery_test.cc: a child process runs the engine and is killed with SIGKILL from a
// reading listener at a chosen reading; a new manager on the same database recovers and resumes.
#include <gtest/gtest.h>
#include <poll.h>
#include <signal.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <atomic>
#include <chrono>
#include <cstring>
#include <functional>
#include <future>
#include <memory>
#include <string>
#include <vector>

#include "core/adaptive/prompt_order.h"
#include "core/geometry.h"
#include "core/plan/analyze_plan.h"
#include "core/plan/plan_json.h"
#include "core/plan/plan_settings.h"
#include "core/plan/plan_summary.h"
#include "daemon/engine/adaptive_rounds.h"
#include "daemon/engine/session_manager.h"
#include "daemon/wire/plan.h"
#include "storage/session_store.h"
#include "tests/adaptive/kernel_model.h"
#include "tests/engine/engine_test_rig.h"

namespace brdf::testing {
namespace {

using namespace std::chrono_literals;
using daemon::SessionId;

constexpr int kMaxReadings = 27;  // the seed's 15 and three rounds of 4

// Three detector positions (the fake rig's arm is motorized), a reference at each.
std::string AdaptivePlan(const std::string& budget) {
  return R"({
  "name": "adaptive on the fake rig",
  "adaptive": {
    "target": {"expandedUncertainty": 0.001},
    "budget": )" +
         budget + R"(,
    "delta": {"start": 0, "stop": 22.5, "step": 11.25},
    "seed": {"retroReadings": 3, "readingsPerDelta": 4},
    "roundReadings": 4
  },
  "reference": {"perDetectorPosition": true},
  "measurement": {"integrationMs": 100, "averages": 1},
  "retry": {"maxAttempts": 2, "backoffMs": 0}
})";
}

const std::string kReadingBudgetPlan =
    AdaptivePlan(R"({"maxReadings": )" + std::to_string(kMaxReadings) + "}");

// The sample-fixed form: a seed of 2 retro-reflection and 4 space-filling poses (8 prompts with
// the first reference), rounds of 4, at most 16 prompts.
const std::string kSampleFixedPlan = R"({
  "name": "adaptive sample-fixed on the fake rig",
  "adaptive": {
    "target": {"expandedUncertainty": 0.001},
    "budget": {"maxPrompts": 16},
    "seed": {"retroReadings": 2},
    "sampleFixed": {"seedReadings": 4},
    "roundReadings": 4
  },
  "reference": {"perDetectorPosition": false},
  "measurement": {"integrationMs": 100, "averages": 1},
  "retry": {"maxAttempts": 2, "backoffMs": 0}
})";

daemon::UncertaintyModelFactory KernelFactory() {
  return [](const adaptive::AdaptiveSpec&) -> std::unique_ptr<adaptive::UncertaintyModel> {
    return std::make_unique<adaptive::testing::KernelModel>(
        [](const IsoDirection&) { return 0.2; });
  };
}

daemon::SessionManager::Options AdaptiveOptions() {
  daemon::SessionManager::Options o = ManagerOptions();
  o.uncertainty_model = KernelFactory();
  return o;
}

int SeedSteps(const std::string& json) {
  return static_cast<int>(plan::AnalyzePlan(PlanFromJson(json), SimRigDescription()).steps.size());
}

bool Ended(const v1::Session& s) {
  return s.state() == v1::SESSION_STATE_COMPLETED || s.state() == v1::SESSION_STATE_PAUSED ||
         s.state() == v1::SESSION_STATE_FAILED || s.state() == v1::SESSION_STATE_ABORTED;
}

std::vector<storage::RoundRecord> Rounds(storage::SessionStore& store, SessionId id) {
  auto rounds = store.GetRounds(id);
  EXPECT_TRUE(rounds.ok()) << rounds.status().ToString();
  return rounds.ok() ? *rounds : std::vector<storage::RoundRecord>{};
}

std::vector<Pose> EncodedPoses(const storage::RoundRecord& round) {
  std::vector<Pose> out;
  for (const storage::RoundPick& p : round.picks) out.push_back(p.pose);
  return out;
}

int SampleReadings(storage::SessionStore& store, SessionId id) {
  auto readings = store.GetReadings(id, 0, 100000);
  EXPECT_TRUE(readings.ok());
  int n = 0;
  for (const auto& r : *readings) n += r.kind == storage::ReadingKind::kSample;
  return n;
}

// The database holds each step once and each done reading step's one reading, every step done.
void ExpectWholeAndDone(storage::SessionStore& store, SessionId id) {
  auto report = store.CheckSession(id);
  ASSERT_TRUE(report.ok()) << report.status().ToString();
  EXPECT_TRUE(report->ok()) << report->Summary();
  EXPECT_EQ(report->steps_present, report->total_steps);
  EXPECT_EQ(report->steps_done, report->total_steps);
}

// Each round's sample steps are its picks, in order, and its steps follow the previous ones.
void ExpectRoundsAreTheirSteps(storage::SessionStore& store, SessionId id, int seed_steps) {
  auto steps = store.GetSteps(id);
  ASSERT_TRUE(steps.ok());
  int next = seed_steps;
  for (const storage::RoundRecord& round : Rounds(store, id)) {
    EXPECT_EQ(round.first_step, next) << "round " << round.round;
    next = round.first_step + round.step_count;
    std::vector<Pose> samples;
    for (int i = round.first_step; i < next; ++i) {
      const storage::StepRecord& s = (*steps)[static_cast<std::size_t>(i)];
      if (s.kind == storage::StepKind::kSample) samples.push_back(s.pose);
    }
    ASSERT_EQ(samples.size(), round.picks.size()) << "round " << round.round;
    for (std::size_t k = 0; k < samples.size(); ++k) {
      const Pose want = ToReadings(round.picks[k].pose, SimRigDescription().convention);
      EXPECT_NEAR(samples[k].alpha, want.alpha, 1e-9);
      EXPECT_NEAR(samples[k].beta, want.beta, 1e-9);
      EXPECT_NEAR(samples[k].delta, want.delta, 1e-9);
      EXPECT_GT(round.picks[k].predicted_gain, 0);
    }
  }
  EXPECT_EQ(next, static_cast<int>(steps->size()));
}

class AdaptiveSessionTest : public ::testing::Test {
 protected:
  void SetUp() override { ASSERT_FALSE(dir_.path().empty()) << dir_.error(); }
  void TearDown() override { Close(); }

  void Open(const std::string& name, daemon::SessionManager::Options options) {
    auto store = storage::SessionStore::Open(dir_.file(name).string());
    ASSERT_TRUE(store.ok()) << store.status().ToString();
    store_ = std::move(*store);
    fake_ = MakeFakeRig();
    manager_ = std::make_unique<daemon::SessionManager>(store_, fake_.rig, std::move(options));
  }

  void Close() {
    if (op_) op_->Stop();
    if (op_) {
      for (const std::string& e : op_->errors()) ADD_FAILURE() << "operator: " << e;
    }
    op_.reset();
    if (manager_) manager_->Shutdown(5s);
    manager_.reset();
    fake_ = FakeRig();
    store_.reset();
  }

  // Submits and runs `json` to its end with an operator answering prompts.
  v1::Session RunToEnd(const std::string& json, SessionId& id) {
    auto s = manager_->SubmitPlan(PlanFromJson(json), kTestOperator, /*start_now=*/true);
    EXPECT_TRUE(s.ok()) << s.status().ToString();
    id = s.ok() ? IdOf(*s) : 0;
    op_ = std::make_unique<Operator>(*manager_, *fake_.bench, id);
    return WaitForSession(*manager_, id, Ended, 60s);
  }

  // Runs `json` in a child killed right after the seed's last reading, before the first round is
  // stored; a new manager on its database resumes it, and the rounds it stores are those of the
  // same plan run uninterrupted (`rounds_wanted` of them), pose for pose, with `readings` sample
  // readings. Defined with the kill -9 helpers below.
  void ExpectTheSameRoundsAfterAKillAtTheSeedsEnd(const std::string& json,
                                                  std::size_t rounds_wanted, int readings);

  TempDir dir_{"brdf-engine-adaptive"};
  FakeRig fake_;
  std::shared_ptr<storage::SessionStore> store_;
  std::unique_ptr<daemon::SessionManager> manager_;
  std::unique_ptr<Operator> op_;
};

TEST_F(AdaptiveSessionTest, RunsSeedAndRoundsToTheReadingBudgetAndCompletes) {
  Open("brdfd.db", AdaptiveOptions());
  SessionId id = 0;
  const v1::Session done = RunToEnd(kReadingBudgetPlan, id);
  ASSERT_EQ(done.state(), v1::SESSION_STATE_COMPLETED)
      << done.state_reason() << (done.has_last_fault() ? done.last_fault().reason() : "");
  EXPECT_NE(done.state_reason().find("adaptive: reading budget spent; uncertainty left"),
            std::string::npos)
      << done.state_reason();

  const std::vector<storage::RoundRecord> rounds = Rounds(*store_, id);
  ASSERT_EQ(rounds.size(), 3u);
  EXPECT_EQ(SampleReadings(*store_, id), kMaxReadings);  // the budget, never more
  ExpectWholeAndDone(*store_, id);
  ExpectRoundsAreTheirSteps(*store_, id, SeedSteps(kReadingBudgetPlan));
  int readings_before = 15;
  for (const storage::RoundRecord& r : rounds) {
    EXPECT_EQ(r.readings_used, readings_before) << "round " << r.round;
    readings_before += static_cast<int>(r.picks.size());
    EXPECT_GT(r.uncertainty_left, 0);
    EXPECT_GT(r.predicted_gain, 0);
  }
  EXPECT_GT(rounds[0].uncertainty_left, rounds[2].uncertainty_left);  // it falls

  // Each round was stored before any of its readings was taken.
  auto readings = store_->GetReadings(id, 0, 100000);
  ASSERT_TRUE(readings.ok());
  for (const storage::ReadingRecord& reading : *readings) {
    for (const storage::RoundRecord& r : rounds) {
      if (reading.step_index >= r.first_step && reading.step_index < r.first_step + r.step_count) {
        EXPECT_LE(r.created_at, reading.recorded_at) << "reading " << reading.id;
      }
    }
  }

  // The watcher saw each round (poses, gain, uncertainty left) and then the stop.
  op_->Stop();
  std::vector<v1::AdaptiveRound> seen;
  std::vector<v1::AdaptiveStop> stops;
  for (const v1::SessionEvent& e : op_->events()) {
    if (e.has_adaptive_round()) seen.push_back(e.adaptive_round());
    if (e.has_adaptive_stop()) stops.push_back(e.adaptive_stop());
  }
  ASSERT_EQ(seen.size(), rounds.size());
  for (std::size_t i = 0; i < seen.size(); ++i) {
    EXPECT_EQ(seen[i].round(), static_cast<std::uint32_t>(rounds[i].round));
    EXPECT_EQ(seen[i].poses_size(), static_cast<int>(rounds[i].picks.size()));
    EXPECT_EQ(seen[i].pose_gains_size(), seen[i].poses_size());
    EXPECT_DOUBLE_EQ(seen[i].predicted_gain(), rounds[i].predicted_gain);
    EXPECT_DOUBLE_EQ(seen[i].uncertainty_left(), rounds[i].uncertainty_left);
  }
  ASSERT_EQ(stops.size(), 1u);
  EXPECT_EQ(stops[0].reason(), "reading budget spent");
  EXPECT_EQ(stops[0].readings(), static_cast<std::uint32_t>(kMaxReadings));
  EXPECT_EQ(stops[0].rounds(), 3u);
  EXPECT_GT(stops[0].uncertainty_left(), 0);
  EXPECT_LT(stops[0].uncertainty_left(), rounds[2].uncertainty_left);
}

TEST_F(AdaptiveSessionTest, StopsWithinTheRigTimeBudget) {
  const v1::Plan probe = PlanFromJson(AdaptivePlan(R"({"maxReadings": 1000})"));
  const double seed_s =
      plan::AnalyzePlan(probe, SimRigDescription(), 1).summary.estimated_duration_s;
  ASSERT_GT(seed_s, 0);
  const double budget_min = (seed_s + 90) / 60;  // room for a round or two, not for many
  const std::string json = AdaptivePlan(R"({"maxRigMinutes": )" + std::to_string(budget_min) + "}");
  Open("brdfd.db", AdaptiveOptions());
  SessionId id = 0;
  const v1::Session done = RunToEnd(json, id);
  ASSERT_EQ(done.state(), v1::SESSION_STATE_COMPLETED) << done.state_reason();
  EXPECT_NE(done.state_reason().find("adaptive: "), std::string::npos) << done.state_reason();
  EXPECT_FALSE(Rounds(*store_, id).empty());
  ExpectWholeAndDone(*store_, id);

  auto steps = store_->GetSteps(id);
  ASSERT_TRUE(steps.ok());
  plan::RigDescription real = SimRigDescription();
  real.time_scale = 1;
  const std::vector<plan::Step> plan_steps = daemon::ToPlanSteps(*steps);
  const plan::PlanSummary spent =
      plan::SummarizeSteps(plan_steps, real, plan::ResolveSettings(probe).measurement);
  EXPECT_LE(spent.estimated_duration_s, budget_min * 60 + 1e-6);
  EXPECT_GT(spent.estimated_duration_s, seed_s);
}

TEST_F(AdaptiveSessionTest, WithoutAnUncertaintyModelAdaptivePlansAreRefused) {
  Open("brdfd.db", ManagerOptions());
  const v1::Plan plan = PlanFromJson(kReadingBudgetPlan);
  EXPECT_TRUE(manager_->ValidatePlan(plan).valid());
  auto refused = manager_->SubmitPlan(plan, kTestOperator, true);
  EXPECT_EQ(refused.status().code(), StatusCode::kFailedPrecondition);
  EXPECT_NE(refused.status().message().find("no uncertainty model is configured"),
            std::string::npos)
      << refused.status().message();
}

// The sample-fixed form (docs/adaptive.md): every pose a RELOCATE_LAMP_AND_DETECTOR prompt with
// its target, the holder never moved, each reading recorded at its target's directions, each round
// stored in prompt order, and the prompt budget what ends the session: the seed's 6 poses and its
// reference are 8 prompts, then two rounds of 4 reach the 16.
TEST_F(AdaptiveSessionTest, SampleFixedFormStopsAtThePromptBudgetWithAPromptPerPose) {
  const std::string& json = kSampleFixedPlan;
  Open("brdfd.db", AdaptiveOptions());
  SessionId id = 0;
  const v1::Session done = RunToEnd(json, id);
  ASSERT_EQ(done.state(), v1::SESSION_STATE_COMPLETED)
      << done.state_reason() << (done.has_last_fault() ? done.last_fault().reason() : "");
  EXPECT_NE(done.state_reason().find("adaptive: prompt budget spent"), std::string::npos)
      << done.state_reason();
  const std::vector<storage::RoundRecord> rounds = Rounds(*store_, id);
  ASSERT_EQ(rounds.size(), 2u);
  ExpectWholeAndDone(*store_, id);
  ExpectRoundsAreTheirSteps(*store_, id, SeedSteps(json));

  auto stored = store_->GetSteps(id);
  ASSERT_TRUE(stored.ok());
  const std::vector<plan::Step> steps = daemon::ToPlanSteps(*stored);
  int prompts = 0;
  int relocations = 0;
  for (const plan::Step& s : steps) {
    EXPECT_NE(s.kind, v1::STEP_KIND_MOVE) << s.label;
    prompts += s.kind == v1::STEP_KIND_PROMPT;
    relocations += s.prompt == v1::PROMPT_KIND_RELOCATE_LAMP_AND_DETECTOR;
  }
  EXPECT_EQ(prompts, 16);
  EXPECT_EQ(relocations, 14);
  EXPECT_EQ(SampleReadings(*store_, id), 14);
  auto readings = store_->GetReadings(id, 0, 100000);
  ASSERT_TRUE(readings.ok());
  for (const storage::ReadingRecord& r : *readings) {
    const plan::Step& step = steps[static_cast<std::size_t>(r.step_index)];
    ASSERT_TRUE(step.target.has_value()) << step.label;
    EXPECT_EQ(r.directions, *step.target) << step.label;
  }
  // Each round as stored is already in prompt order from where lamp and detector stood.
  const plan::RigDescription rig = SimRigDescription();
  for (const storage::RoundRecord& round : rounds) {
    const Pose from =
        ToModelAngles(steps[static_cast<std::size_t>(round.first_step - 1)].pose, rig.convention);
    const std::vector<Pose> picks = EncodedPoses(round);
    EXPECT_EQ(adaptive::OrderForPrompts(from, picks), picks) << "round " << round.round;
  }
}

// Paused at each round boundary (deferred, from the reading listener, right after the seed's last
// reading and the first round's last reading) and resumed: the session chooses the same rounds,
// pose for pose, as the same plan run uninterrupted, with each reading once. A pause between
// rounds must not lose, repeat or change the design.
TEST_F(AdaptiveSessionTest, PausedBetweenRoundsResumesTheSameDesign) {
  Open("uninterrupted.db", AdaptiveOptions());
  SessionId reference_id = 0;
  ASSERT_EQ(RunToEnd(kReadingBudgetPlan, reference_id).state(), v1::SESSION_STATE_COMPLETED);
  const std::vector<storage::RoundRecord> expected = Rounds(*store_, reference_id);
  Close();
  ASSERT_EQ(expected.size(), 3u);
  const int seed_steps = SeedSteps(kReadingBudgetPlan);
  const std::vector<int> boundaries = {seed_steps - 1,
                                       expected[0].first_step + expected[0].step_count - 1};

  Open("paused.db", AdaptiveOptions());
  std::atomic<int> pauses{0};
  manager_->AddReadingListener([&](SessionId session, const storage::ReadingRecord& r) {
    if (std::find(boundaries.begin(), boundaries.end(), r.step_index) == boundaries.end()) return;
    // Another thread asks, as an operator's client would; the listener waits for the answer.
    auto paused = std::async(std::launch::async, [&, session] {
      return manager_->Pause(session, daemon::PauseMode::kDeferred, kTestOperator);
    });
    EXPECT_TRUE(paused.get().ok());
    pauses.fetch_add(1);
  });
  auto submitted = manager_->SubmitPlan(PlanFromJson(kReadingBudgetPlan), kTestOperator, true);
  ASSERT_TRUE(submitted.ok()) << submitted.status().ToString();
  const SessionId id = IdOf(*submitted);
  op_ = std::make_unique<Operator>(*manager_, *fake_.bench, id);

  for (int k = 1; k <= 2; ++k) {
    const v1::Session paused = WaitForSession(*manager_, id, Ended, 60s);
    ASSERT_EQ(paused.state(), v1::SESSION_STATE_PAUSED)
        << "pause " << k << ": " << paused.state_reason();
    EXPECT_EQ(pauses.load(), k);
    // Paused at the boundary: every stored step done, the rounds stored so far the expected ones.
    // The next round may already be stored (chosen before it is measured), none of it measured.
    const std::vector<storage::RoundRecord> so_far = Rounds(*store_, id);
    ASSERT_LE(so_far.size(), expected.size());
    auto first = store_->FirstUnfinishedStep(id);
    ASSERT_TRUE(first.ok());
    const int next_step = boundaries[static_cast<std::size_t>(k - 1)] + 1;
    if (first->has_value()) {
      EXPECT_EQ(**first, next_step) << "pause " << k;
      ASSERT_EQ(so_far.size(), static_cast<std::size_t>(k)) << "pause " << k;
      EXPECT_EQ(so_far.back().first_step, next_step) << "pause " << k;
    } else {
      EXPECT_EQ(so_far.size(), static_cast<std::size_t>(k - 1)) << "pause " << k;
    }
    for (std::size_t i = 0; i < so_far.size(); ++i) {
      EXPECT_EQ(EncodedPoses(so_far[i]), EncodedPoses(expected[i])) << "pause " << k;
    }
    auto resumed = manager_->Resume(id, kTestOperator);
    ASSERT_TRUE(resumed.ok()) << resumed.status().ToString();
  }
  const v1::Session done = WaitForSession(*manager_, id, Ended, 60s);
  ASSERT_EQ(done.state(), v1::SESSION_STATE_COMPLETED) << done.state_reason();

  const std::vector<storage::RoundRecord> rounds = Rounds(*store_, id);
  ASSERT_EQ(rounds.size(), expected.size());
  for (std::size_t i = 0; i < rounds.size(); ++i) {
    EXPECT_EQ(EncodedPoses(rounds[i]), EncodedPoses(expected[i])) << "round " << i + 1;
    EXPECT_EQ(rounds[i].first_step, expected[i].first_step) << "round " << i + 1;
    EXPECT_EQ(rounds[i].step_count, expected[i].step_count) << "round " << i + 1;
  }
  EXPECT_EQ(SampleReadings(*store_, id), kMaxReadings);
  ExpectWholeAndDone(*store_, id);
  ExpectRoundsAreTheirSteps(*store_, id, seed_steps);
}

// --- kill -9 --------------------------------------------------------------------------------

// The child: runs `json` on the engine and is killed (SIGKILL, from the reading listener) right
// after the reading `kill_now` picks is committed. Writes the session id to `fd`.
[[noreturn]] void RunChild(const std::string& db, const std::string& json, int fd,
                           std::function<bool(const storage::ReadingRecord&)> kill_now) {
  auto store = storage::SessionStore::Open(db);
  if (!store.ok()) ::_exit(10);
  FakeRig fake = MakeFakeRig();
  daemon::SessionManager manager(std::move(*store), fake.rig, AdaptiveOptions());
  manager.AddReadingListener([&](SessionId, const storage::ReadingRecord& r) {
    if (kill_now(r)) ::raise(SIGKILL);
  });
  auto plan = plan::ParsePlanJson(json);
  if (!plan.ok()) ::_exit(13);
  auto session = manager.SubmitPlan(*plan, kTestOperator, /*start_now=*/true);
  if (!session.ok()) ::_exit(14);
  const SessionId id = IdOf(*session);
  if (::write(fd, &id, sizeof id) != static_cast<ssize_t>(sizeof id)) ::_exit(15);
  Operator op(manager, *fake.bench, id);
  for (;;) ::pause();  // until SIGKILL
}

// Forks the child, waits until it is killed; returns the session id (0 on failure).
SessionId RunChildUntilKilled(const std::string& db, const std::string& json,
                              std::function<bool(const storage::ReadingRecord&)> kill_now) {
  int fds[2];
  EXPECT_EQ(::pipe(fds), 0) << std::strerror(errno);
  const pid_t child = ::fork();  // no thread of ours runs yet
  EXPECT_GE(child, 0) << std::strerror(errno);
  if (child == 0) {
    ::close(fds[0]);
    RunChild(db, json, fds[1], std::move(kill_now));
  }
  ::close(fds[1]);
  SessionId id = 0;
  pollfd pfd{fds[0], POLLIN, 0};
  if (::poll(&pfd, 1, 15000) != 1 || ::read(fds[0], &id, sizeof id) != sizeof id) id = 0;
  ::close(fds[0]);
  int wstatus = 0;
  if (id == 0) ::kill(child, SIGKILL);
  // Killed by its own listener; bounded by the test's timeout otherwise.
  EXPECT_EQ(::waitpid(child, &wstatus, 0), child);
  EXPECT_TRUE(WIFSIGNALED(wstatus) && WTERMSIG(wstatus) == SIGKILL);
  return id;
}

// A new manager on the database recovers the session as paused; resuming completes it.
v1::Session RecoverAndFinish(daemon::SessionManager& manager, FakeRig& fake, SessionId id) {
  auto recovered = manager.Recover();
  EXPECT_TRUE(recovered.ok() && *recovered == std::vector<SessionId>{id});
  Operator op(manager, *fake.bench, id);
  auto resumed = manager.Resume(id, kTestOperator);
  EXPECT_TRUE(resumed.ok()) << resumed.status().ToString();
  const v1::Session done = WaitForSession(manager, id, Ended, 60s);
  op.Stop();
  for (const std::string& e : op.errors()) ADD_FAILURE() << "operator: " << e;
  return done;
}

void AdaptiveSessionTest::ExpectTheSameRoundsAfterAKillAtTheSeedsEnd(const std::string& json,
                                                                     std::size_t rounds_wanted,
                                                                     int readings) {
  const std::string db = dir_.file("killed.db").string();
  const int seed_steps = SeedSteps(json);
  const SessionId id =
      RunChildUntilKilled(db, json, [=](const auto& r) { return r.step_index == seed_steps - 1; });
  ASSERT_GT(id, 0);

  // The same plan uninterrupted, on a database of its own: the rounds to expect.
  Open("uninterrupted.db", AdaptiveOptions());
  SessionId reference_id = 0;
  ASSERT_EQ(RunToEnd(json, reference_id).state(), v1::SESSION_STATE_COMPLETED);
  const std::vector<storage::RoundRecord> expected = Rounds(*store_, reference_id);
  Close();
  ASSERT_EQ(expected.size(), rounds_wanted);

  auto opened = storage::SessionStore::Open(db);
  ASSERT_TRUE(opened.ok()) << opened.status().ToString();
  std::shared_ptr<storage::SessionStore> store = std::move(*opened);
  EXPECT_TRUE(Rounds(*store, id).empty());  // nothing of a round was written
  auto first = store->FirstUnfinishedStep(id);
  ASSERT_TRUE(first.ok());
  EXPECT_FALSE(first->has_value());  // every seed step done

  FakeRig fake = MakeFakeRig();
  daemon::SessionManager manager(store, fake.rig, AdaptiveOptions());
  const v1::Session done = RecoverAndFinish(manager, fake, id);
  manager.Shutdown(5s);
  ASSERT_EQ(done.state(), v1::SESSION_STATE_COMPLETED) << done.state_reason();
  const std::vector<storage::RoundRecord> rounds = Rounds(*store, id);
  ASSERT_EQ(rounds.size(), expected.size());
  for (std::size_t i = 0; i < rounds.size(); ++i) {
    ASSERT_EQ(rounds[i].picks.size(), expected[i].picks.size()) << "round " << i + 1;
    for (std::size_t k = 0; k < rounds[i].picks.size(); ++k) {
      EXPECT_EQ(rounds[i].picks[k].pose, expected[i].picks[k].pose)
          << "round " << i + 1 << " pick " << k;
    }
    EXPECT_EQ(rounds[i].first_step, expected[i].first_step);
    EXPECT_EQ(rounds[i].step_count, expected[i].step_count);
  }
  EXPECT_EQ(SampleReadings(*store, id), readings);
  ExpectWholeAndDone(*store, id);
}

TEST_F(AdaptiveSessionTest, KilledAfterTheSeedChoosesTheSameRoundOnRestart) {
  ExpectTheSameRoundsAfterAKillAtTheSeedsEnd(kReadingBudgetPlan, 3, kMaxReadings);
}

// The sample-fixed form: the same rounds in the same prompt order.
TEST_F(AdaptiveSessionTest, SampleFixedFormKilledAfterTheSeedChoosesTheSameRoundsOnRestart) {
  ExpectTheSameRoundsAfterAKillAtTheSeedsEnd(kSampleFixedPlan, 2, 14);
}

TEST_F(AdaptiveSessionTest, KilledMidRoundContinuesTheStoredRoundWithoutRepeats) {
  const std::string db = dir_.file("killed.db").string();
  const int seed_steps = SeedSteps(kReadingBudgetPlan);
  // Killed after the second sample reading of the first round.
  int round_samples = 0;
  const SessionId id = RunChildUntilKilled(db, kReadingBudgetPlan, [&](const auto& r) {
    return r.kind == storage::ReadingKind::kSample && r.step_index >= seed_steps &&
           ++round_samples == 2;
  });
  ASSERT_GT(id, 0);

  auto opened = storage::SessionStore::Open(db);
  ASSERT_TRUE(opened.ok()) << opened.status().ToString();
  std::shared_ptr<storage::SessionStore> store = std::move(*opened);
  const std::vector<storage::RoundRecord> before = Rounds(*store, id);
  ASSERT_EQ(before.size(), 1u);
  auto steps_before = store->GetSteps(id);
  ASSERT_TRUE(steps_before.ok());
  auto first = store->FirstUnfinishedStep(id);
  ASSERT_TRUE(first.ok() && first->has_value());
  EXPECT_GT(**first, before[0].first_step);  // part of the round measured
  EXPECT_LT(**first, before[0].first_step + before[0].step_count);
  EXPECT_EQ(SampleReadings(*store, id), 15 + 2);

  FakeRig fake = MakeFakeRig();
  daemon::SessionManager manager(store, fake.rig, AdaptiveOptions());
  const v1::Session done = RecoverAndFinish(manager, fake, id);
  manager.Shutdown(5s);
  ASSERT_EQ(done.state(), v1::SESSION_STATE_COMPLETED) << done.state_reason();

  // The stored round was measured as stored: its steps unchanged, each reading once.
  const std::vector<storage::RoundRecord> rounds = Rounds(*store, id);
  ASSERT_EQ(rounds.size(), 3u);
  EXPECT_EQ(EncodedPoses(rounds[0]), EncodedPoses(before[0]));
  auto steps_after = store->GetSteps(id);
  ASSERT_TRUE(steps_after.ok());
  for (std::size_t i = 0; i < steps_before->size(); ++i) {
    EXPECT_EQ((*steps_after)[i].pose, (*steps_before)[i].pose) << "step " << i;
    EXPECT_EQ((*steps_after)[i].kind, (*steps_before)[i].kind) << "step " << i;
  }
  EXPECT_EQ(SampleReadings(*store, id), kMaxReadings);
  ExpectWholeAndDone(*store, id);
  ExpectRoundsAreTheirSteps(*store, id, seed_steps);
}

}  // namespace
}  // namespace brdf::testing
