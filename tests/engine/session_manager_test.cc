// Sessions end to end on the engine: SessionManager → Executor → Rig → the in-process fake meter
// and stage (tests/support/fakes/rig.h), with a real SQLite file. The test plays the operator
// (tests/engine/engine_test_rig.h). The same sessions on the real drivers and brdf-sim run in
// tests/daemon/sessions/daemon_session_test.cc.
#include "daemon/engine/session_manager.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <atomic>
#include <chrono>
#include <cmath>
#include <map>
#include <mutex>
#include <thread>

#include "core/geometry.h"
#include "core/plan/plan_json.h"
#include "daemon/wire/plan.h"
#include "drivers/pr650/spectroradiometer.h"
#include "drivers/stage/modbus_stage.h"
#include "storage/session_store.h"
#include "tests/engine/engine_test_rig.h"
#include "tests/support/plan_fixtures.h"

namespace brdf::testing {
namespace {

using namespace std::chrono_literals;
using daemon::PauseMode;
using daemon::SessionId;

// Two detector positions, two tilts, β every 45°; a dark with each reference.
const std::string kRotationPlan = plans::SmallRotation();
// Readings that take long enough (~20 simulated seconds, ~0.4 s real) to pause in the middle.
const std::string kSlowPlan = plans::SlowRotation(/*alpha_stop=*/0, /*beta_step=*/60,
                                                  /*averages=*/99);
const std::string kFixedPlan =
    plans::SampleFixed({{0, 45, 180, "0/45"}, {30, 30, 180, "specular 30"}},
                       /*reference_per_detector_position=*/false);
const std::string kTinyPlan = plans::TinyPoseList();

bool Terminal(const v1::Session& s) {
  return s.state() == v1::SESSION_STATE_COMPLETED || s.state() == v1::SESSION_STATE_ABORTED ||
         s.state() == v1::SESSION_STATE_FAILED;
}

class EngineTest : public ::testing::Test {
 protected:
  void SetUp() override { Open(true); }

  void Open(bool pipelining) {
    Close();
    ASSERT_FALSE(dir_.path().empty()) << dir_.error();
    auto store = storage::SessionStore::Open(dir_.file("brdfd.db").string());
    ASSERT_TRUE(store.ok()) << store.status().ToString();
    store_ = std::move(*store);
    fake_ = MakeFakeRig();
    rig_ = fake_.rig;
    manager_ = std::make_unique<daemon::SessionManager>(store_, rig_, ManagerOptions(pipelining));
    listener_ = manager_->AddReadingListener([this](SessionId, const storage::ReadingRecord& r) {
      std::lock_guard lock(listened_mu_);
      listened_.push_back(r.id);
    });
  }

  void Close() {
    operators_.clear();
    if (manager_) manager_->Shutdown(5s);
    manager_.reset();
    rig_.reset();
    fake_ = FakeRig();
    store_.reset();
  }

  void TearDown() override {
    for (auto& op : operators_) {
      for (const std::string& e : op->errors()) ADD_FAILURE() << "operator: " << e;
    }
    Close();
  }

  SessionId Submit(const std::string& json, bool start_now = true) {
    Result<v1::Session> s = manager_->SubmitPlan(PlanFromJson(json), kTestOperator, start_now);
    EXPECT_TRUE(s.ok()) << s.status().ToString();
    return s.ok() ? IdOf(*s) : 0;
  }

  Operator& Watch(SessionId id, bool answer = true) {
    operators_.push_back(std::make_unique<Operator>(*manager_, *fake_.bench, id, answer));
    return *operators_.back();
  }

  v1::Session WaitDone(SessionId id, std::chrono::milliseconds timeout = 20s) {
    v1::Session s = WaitForSession(*manager_, id, Terminal, timeout);
    EXPECT_TRUE(Terminal(s)) << "session still " << v1::SessionState_Name(s.state());
    return s;
  }

  std::vector<storage::ReadingRecord> Readings(SessionId id) {
    auto r = store_->GetReadings(id, 0, 100000);
    EXPECT_TRUE(r.ok()) << r.status().ToString();
    return r.ok() ? *r : std::vector<storage::ReadingRecord>{};
  }

  std::vector<storage::StepRecord> Steps(SessionId id) {
    auto r = store_->GetSteps(id);
    EXPECT_TRUE(r.ok()) << r.status().ToString();
    return r.ok() ? *r : std::vector<storage::StepRecord>{};
  }

  static int DoneReadingSteps(const std::vector<storage::StepRecord>& steps) {
    int n = 0;
    for (const auto& s : steps) {
      const bool reading = s.kind == storage::StepKind::kReference ||
                           s.kind == storage::StepKind::kDark ||
                           s.kind == storage::StepKind::kSample;
      if (reading && s.state == storage::StepState::kDone) ++n;
    }
    return n;
  }

  void ExpectIntact(SessionId id) {
    auto report = store_->CheckSession(id);
    ASSERT_TRUE(report.ok()) << report.status().ToString();
    EXPECT_TRUE(report->ok()) << report->Summary();
  }

  // Every sample names the latest reference and dark before it; poses are where the plan put
  // them and directions follow from the poses by geometry.md.
  void ExpectReadingsConsistent(SessionId id) {
    const auto steps = Steps(id);
    std::optional<std::int64_t> reference, dark;
    for (const storage::ReadingRecord& r : Readings(id)) {
      if (r.kind == storage::ReadingKind::kReference) reference = r.id;
      if (r.kind == storage::ReadingKind::kDark) dark = r.id;
      if (r.kind == storage::ReadingKind::kSample) {
        EXPECT_EQ(r.reference_reading_id, reference) << "reading " << r.id;
        EXPECT_EQ(r.dark_reading_id, dark) << "reading " << r.id;
      }
      ASSERT_LT(static_cast<std::size_t>(r.step_index), steps.size());
      const Pose& planned = steps[static_cast<std::size_t>(r.step_index)].pose;
      EXPECT_NEAR(r.pose.alpha, planned.alpha, 0.05) << "reading " << r.id;
      EXPECT_NEAR(r.pose.beta, planned.beta, 0.05) << "reading " << r.id;
      EXPECT_NEAR(r.pose.delta, planned.delta, 0.05) << "reading " << r.id;
      const Directions d = PoseToDirections(r.pose, SimRigDescription().convention);
      EXPECT_NEAR(r.directions.theta_i, d.theta_i, 1e-9) << "reading " << r.id;
      EXPECT_NEAR(r.directions.phi_i, d.phi_i, 1e-9) << "reading " << r.id;
      EXPECT_NEAR(r.directions.theta_o, d.theta_o, 1e-9) << "reading " << r.id;
      EXPECT_NEAR(r.directions.phi_o, d.phi_o, 1e-9) << "reading " << r.id;
      EXPECT_EQ(r.spectrum.size(), r.grid.count);
      EXPECT_FALSE(r.meter_serial.empty());
    }
  }

  static int PlannedReadings(const v1::Session& s) {
    return static_cast<int>(s.summary().sample_readings() + s.summary().reference_readings() +
                            s.summary().dark_readings());
  }

  std::size_t Listened() {
    std::lock_guard lock(listened_mu_);
    return listened_.size();
  }

  TempDir dir_{"brdf-engine-test"};
  FakeRig fake_;
  std::shared_ptr<storage::SessionStore> store_;
  std::shared_ptr<daemon::Rig> rig_;
  std::unique_ptr<daemon::SessionManager> manager_;
  std::vector<std::unique_ptr<Operator>> operators_;
  int listener_ = 0;
  std::mutex listened_mu_;
  std::vector<std::int64_t> listened_;
};

class SampleRotationTest : public EngineTest, public ::testing::WithParamInterface<bool> {
 protected:
  void SetUp() override { Open(/*pipelining=*/GetParam()); }
};

TEST_P(SampleRotationTest, RunsToCompletionWithEveryPlannedReading) {
  const SessionId id = Submit(kRotationPlan);
  ASSERT_GT(id, 0);
  Operator& op = Watch(id);
  const v1::Session done = WaitDone(id);
  ASSERT_EQ(done.state(), v1::SESSION_STATE_COMPLETED);

  EXPECT_GT(done.summary().sample_readings(), 0u);
  EXPECT_EQ(static_cast<int>(Readings(id).size()), PlannedReadings(done));
  EXPECT_EQ(done.progress().done_steps(), done.progress().total_steps());
  EXPECT_EQ(done.progress().done_samples(), done.summary().sample_readings());
  EXPECT_EQ(Listened(), Readings(id).size());
  ExpectIntact(id);
  ExpectReadingsConsistent(id);

  // The watcher saw every prompt, and step completions counting up to the total.
  op.Stop();
  EXPECT_EQ(op.prompts_answered().size(), done.summary().operator_interventions());
  std::uint32_t last_done = 0;
  int completions = 0;
  for (const v1::SessionEvent& e : op.events()) {
    if (!e.has_step_completed()) continue;
    ++completions;
    EXPECT_GT(e.step_completed().progress().done_steps(), last_done);
    last_done = e.step_completed().progress().done_steps();
    if (e.step_completed().reading_id() > 0) {
      EXPECT_GE(e.step_completed().quality_code(), 0);
    }
  }
  EXPECT_EQ(completions, static_cast<int>(done.progress().total_steps()));
  EXPECT_EQ(last_done, done.progress().total_steps());
  ASSERT_FALSE(op.events().empty());
  EXPECT_EQ(op.events().back().state_changed().to(), v1::SESSION_STATE_COMPLETED);
}

INSTANTIATE_TEST_SUITE_P(Pipelining, SampleRotationTest, ::testing::Bool(),
                         [](const ::testing::TestParamInfo<bool>& p) {
                           return p.param ? "pipelined" : "sequential";
                         });

TEST_F(EngineTest, SampleFixedPlanWaitsForEachPromptAndUsesTheTargets) {
  const SessionId id = Submit(kFixedPlan);
  ASSERT_GT(id, 0);
  const auto steps = Steps(id);
  int answered = 0;
  for (;;) {
    v1::Session s = WaitForSession(*manager_, id, [](const v1::Session& x) {
      return x.state() == v1::SESSION_STATE_AWAITING_OPERATOR || Terminal(x);
    });
    if (Terminal(s)) break;
    ASSERT_EQ(s.state(), v1::SESSION_STATE_AWAITING_OPERATOR);
    ASSERT_TRUE(s.has_pending_prompt());
    const v1::Prompt prompt = s.pending_prompt();
    EXPECT_FALSE(prompt.text().empty());
    EXPECT_EQ(s.current_step(), prompt.step_index());
    // A wrong step index never confirms the open prompt.
    auto wrong = manager_->AnswerPrompt(id, prompt.step_index() + 1, "", kTestOperator);
    EXPECT_EQ(wrong.status().code(), StatusCode::kFailedPrecondition);
    // The session waits: nothing moves on while the prompt is open.
    std::this_thread::sleep_for(50ms);
    EXPECT_EQ(manager_->GetSession(id)->state(), v1::SESSION_STATE_AWAITING_OPERATOR);
    if (prompt.kind() == v1::PROMPT_KIND_MOUNT_WHITE) {
      fake_.bench->SetMounted(FakeTarget::kWhite);
    } else if (prompt.kind() == v1::PROMPT_KIND_MOUNT_SAMPLE) {
      fake_.bench->SetMounted(FakeTarget::kSample);
    }
    auto ok = manager_->AnswerPrompt(id, prompt.step_index(), "done", kTestOperator);
    ASSERT_TRUE(ok.ok()) << ok.status().ToString();
    EXPECT_NE(ok->state(), v1::SESSION_STATE_AWAITING_OPERATOR);
    ++answered;
    ASSERT_LT(answered, 50);
  }
  const v1::Session done = *manager_->GetSession(id);
  ASSERT_EQ(done.state(), v1::SESSION_STATE_COMPLETED);
  EXPECT_EQ(static_cast<std::uint32_t>(answered), done.summary().operator_interventions());
  ExpectIntact(id);
  const auto readings = Readings(id);
  EXPECT_EQ(static_cast<int>(readings.size()), PlannedReadings(done));
  int samples = 0;
  for (const storage::ReadingRecord& r : readings) {
    const auto& step = steps[static_cast<std::size_t>(r.step_index)];
    ASSERT_TRUE(step.target.has_value());
    EXPECT_EQ(r.directions, *step.target);  // lamp and detector were put at the target by hand
    if (r.kind == storage::ReadingKind::kSample) {
      ++samples;
      EXPECT_TRUE(r.reference_reading_id.has_value());
    }
  }
  EXPECT_EQ(samples, 2);
  // The audit log names who answered.
  auto audit = store_->GetAudit(id, 100);
  ASSERT_TRUE(audit.ok());
  int answers = 0;
  for (const auto& a : *audit) {
    if (a.action == "session.answer_prompt" && a.detail.rfind("refused", 0) != 0) {
      ++answers;
      EXPECT_EQ(a.actor, kTestOperator.name);
      EXPECT_EQ(a.role, kTestOperator.role);
    }
  }
  EXPECT_EQ(answers, answered);
}

TEST_F(EngineTest, DeferredPauseFinishesTheStepThenResumeCompletes) {
  const SessionId id = Submit(kRotationPlan);
  Operator& op = Watch(id);
  WaitForSession(*manager_, id, [](const v1::Session& s) {
    return s.progress().done_steps() >= 8 && s.state() == v1::SESSION_STATE_RUNNING;
  });
  auto paused = manager_->Pause(id, PauseMode::kDeferred, kTestOperator);
  ASSERT_TRUE(paused.ok()) << paused.status().ToString();
  EXPECT_TRUE(paused->state() == v1::SESSION_STATE_PAUSING ||
              paused->state() == v1::SESSION_STATE_PAUSED)
      << v1::SessionState_Name(paused->state());
  v1::Session s = WaitForSession(
      *manager_, id, [](const v1::Session& x) { return x.state() == v1::SESSION_STATE_PAUSED; });
  ASSERT_EQ(s.state(), v1::SESSION_STATE_PAUSED);
  const auto at_pause = s.progress().done_steps();
  EXPECT_LT(at_pause, s.progress().total_steps());
  // Paused means paused: nothing is taken, and what was taken is whole.
  std::this_thread::sleep_for(300ms);
  EXPECT_EQ(manager_->GetSession(id)->progress().done_steps(), at_pause);
  EXPECT_EQ(static_cast<int>(Readings(id).size()), DoneReadingSteps(Steps(id)));
  ExpectIntact(id);
  EXPECT_EQ(manager_->Pause(id, PauseMode::kDeferred, kTestOperator)->state(),
            v1::SESSION_STATE_PAUSED);  // idempotent

  auto resumed = manager_->Resume(id, kTestOperator);
  ASSERT_TRUE(resumed.ok()) << resumed.status().ToString();
  const v1::Session done = WaitDone(id);
  ASSERT_EQ(done.state(), v1::SESSION_STATE_COMPLETED);
  EXPECT_EQ(static_cast<int>(Readings(id).size()), PlannedReadings(done));
  ExpectIntact(id);
  ExpectReadingsConsistent(id);
  // The watcher saw running → pausing → paused → running.
  op.Stop();
  std::vector<v1::SessionState> states;
  for (const auto& e : op.events()) {
    if (e.has_state_changed()) states.push_back(e.state_changed().to());
  }
  auto pausing = std::find(states.begin(), states.end(), v1::SESSION_STATE_PAUSING);
  ASSERT_NE(pausing, states.end());
  auto paused_at = std::find(pausing, states.end(), v1::SESSION_STATE_PAUSED);
  ASSERT_NE(paused_at, states.end());
  EXPECT_NE(std::find(paused_at, states.end(), v1::SESSION_STATE_RUNNING), states.end());
}

TEST_F(EngineTest, ImmediatePauseCancelsTheMeasurementAndResumeRedoesTheStep) {
  const SessionId id = Submit(kSlowPlan);
  Watch(id);
  const auto steps = Steps(id);
  auto is_sample = [&steps](int index) {
    return index >= 0 && steps[static_cast<std::size_t>(index)].kind == storage::StepKind::kSample;
  };
  // Wait until the rig is on a sample reading, then give the meter time to be inside M0.
  v1::Session s = WaitForSession(*manager_, id, [&](const v1::Session& x) {
    return x.state() == v1::SESSION_STATE_RUNNING && is_sample(x.current_step());
  });
  ASSERT_TRUE(is_sample(s.current_step()));
  const int step = s.current_step();
  std::this_thread::sleep_for(150ms);  // a reading takes ~500 ms here
  auto paused = manager_->Pause(id, PauseMode::kImmediate, kTestOperator);
  ASSERT_TRUE(paused.ok()) << paused.status().ToString();
  EXPECT_EQ(paused->state(), v1::SESSION_STATE_PAUSED);
  EXPECT_EQ(paused->current_step(), step);  // not done: resume redoes it

  // Longer than the measurement would have taken: still nothing written for that step.
  std::this_thread::sleep_for(700ms);
  for (const auto& r : Readings(id)) EXPECT_NE(r.step_index, step);
  EXPECT_EQ(Steps(id)[static_cast<std::size_t>(step)].state, storage::StepState::kPending);
  ExpectIntact(id);

  ASSERT_TRUE(manager_->Resume(id, kTestOperator).ok());
  const v1::Session done = WaitDone(id);
  ASSERT_EQ(done.state(), v1::SESSION_STATE_COMPLETED);
  const auto readings = Readings(id);
  EXPECT_EQ(static_cast<int>(readings.size()), PlannedReadings(done));
  EXPECT_EQ(std::count_if(readings.begin(), readings.end(),
                          [step](const auto& r) { return r.step_index == step; }),
            1);
  ExpectIntact(id);
  ExpectReadingsConsistent(id);
}

TEST_F(EngineTest, AbortKeepsTheDataAndIsFinal) {
  const SessionId id = Submit(kRotationPlan);
  Watch(id);
  WaitForSession(*manager_, id,
                 [](const v1::Session& s) { return s.progress().done_samples() >= 2; });
  auto aborted = manager_->Abort(id, "lamp failed", kTestOperator);
  ASSERT_TRUE(aborted.ok()) << aborted.status().ToString();
  EXPECT_EQ(aborted->state(), v1::SESSION_STATE_ABORTED);
  EXPECT_NE(aborted->end_reason().find("lamp failed"), std::string::npos);
  std::this_thread::sleep_for(300ms);  // the run winds down; nothing more is written
  const auto readings = Readings(id);
  EXPECT_GE(readings.size(), 2u);
  EXPECT_EQ(static_cast<int>(readings.size()), DoneReadingSteps(Steps(id)));
  EXPECT_LT(manager_->GetSession(id)->progress().done_steps(),
            manager_->GetSession(id)->progress().total_steps());
  ExpectIntact(id);
  EXPECT_EQ(manager_->Resume(id, kTestOperator).status().code(), StatusCode::kFailedPrecondition);
  EXPECT_EQ(manager_->Start(id, kTestOperator).status().code(), StatusCode::kFailedPrecondition);
  // The rig is free again: another session runs.
  const SessionId next = Submit(kTinyPlan);
  Watch(next);
  EXPECT_EQ(WaitDone(next).state(), v1::SESSION_STATE_COMPLETED);
}

TEST_F(EngineTest, DeviceFaultThatSurvivesRetriesPausesWithTheFaultThenResumeCompletes) {
  // Quality code 14 fails every measurement it hits (until the operator clears it); the plan
  // allows 2 attempts per step.
  FakeFaults faults;
  faults.fail_next = 1000;
  faults.failure = DeviceError(14, "fake meter: measurement failed with quality code 14");
  fake_.meter_faults->Set(faults);
  const SessionId id = Submit(kTinyPlan);
  Operator& op = Watch(id);
  v1::Session s = WaitForSession(*manager_, id, [](const v1::Session& x) {
    return x.state() == v1::SESSION_STATE_PAUSED || Terminal(x);
  });
  ASSERT_EQ(s.state(), v1::SESSION_STATE_PAUSED);
  ASSERT_TRUE(s.has_last_fault());
  EXPECT_EQ(s.last_fault().code(), "device_error");
  EXPECT_EQ(s.last_fault().device_code(), 14);
  EXPECT_FALSE(s.last_fault().will_retry());
  EXPECT_EQ(s.last_fault().attempt(), 2u);
  EXPECT_EQ(s.last_quality_code(), 14);
  auto record = store_->GetSession(id);
  ASSERT_TRUE(record.ok());
  EXPECT_NE(record->state_reason.find("14"), std::string::npos) << record->state_reason;
  ExpectIntact(id);

  fake_.meter_faults->Set(FakeFaults());  // the operator fixes it
  ASSERT_TRUE(manager_->Resume(id, kTestOperator).ok());
  const v1::Session done = WaitDone(id);
  ASSERT_EQ(done.state(), v1::SESSION_STATE_COMPLETED);
  EXPECT_EQ(static_cast<int>(Readings(id).size()), PlannedReadings(done));
  ExpectIntact(id);
  op.Stop();
  std::vector<bool> will_retry;
  for (const auto& e : op.events()) {
    if (e.has_fault()) will_retry.push_back(e.fault().will_retry());
  }
  EXPECT_EQ(will_retry, (std::vector<bool>{true, false}));
}

TEST_F(EngineTest, AReadingOnAnotherGridMidSessionIsRefusedAndPausesTheSessionNamingBothGrids) {
  // The first measurement on the meter's 101 bands, every later one on a CS-2000's 401 (a meter
  // of another model put in mid-session): the store refuses the reading at commit, and the
  // session pauses with the fault rather than mixing grids.
  FakeFaults faults;
  faults.grid = WavelengthGrid{380, 1, 401};
  faults.grid_after_calls = 1;
  fake_.meter_faults->Set(faults);
  const SessionId id = Submit(kTinyPlan);
  Operator& op = Watch(id);
  v1::Session s = WaitForSession(*manager_, id, [](const v1::Session& x) {
    return x.state() == v1::SESSION_STATE_PAUSED || Terminal(x);
  });
  ASSERT_EQ(s.state(), v1::SESSION_STATE_PAUSED);
  ASSERT_TRUE(s.has_last_fault());
  const std::string& why = s.last_fault().reason();
  EXPECT_NE(why.find("380–780 nm every 1 nm (401 bands)"), std::string::npos) << why;
  EXPECT_NE(why.find("380–780 nm every 4 nm (101 bands)"), std::string::npos) << why;
  auto record = store_->GetSession(id);
  ASSERT_TRUE(record.ok());
  EXPECT_NE(record->state_reason.find("401 bands"), std::string::npos) << record->state_reason;
  EXPECT_NE(record->state_reason.find("101 bands"), std::string::npos) << record->state_reason;
  // Only the first reading was kept, and on its own grid.
  const std::vector<storage::ReadingRecord> kept = Readings(id);
  ASSERT_EQ(kept.size(), 1U);
  EXPECT_EQ(kept.front().grid.count, 101U);
  ASSERT_TRUE(record->grid.has_value());
  EXPECT_EQ(record->grid->count, 101U);
  ExpectIntact(id);
  op.Stop();
}

TEST_F(EngineTest, SecondSessionQueuesAndStartsWhenTheRigFrees) {
  const SessionId first = Submit(kTinyPlan);
  const SessionId second = Submit(kTinyPlan, /*start_now=*/false);
  Watch(first);
  Watch(second);
  auto queued = manager_->Start(second, kTestOperator);
  ASSERT_TRUE(queued.ok()) << queued.status().ToString();
  EXPECT_EQ(queued->state(), v1::SESSION_STATE_QUEUED);
  EXPECT_EQ(manager_->GetRigStatus().active_session_id(), std::to_string(first));

  const v1::Session a = WaitDone(first);
  const v1::Session b = WaitDone(second);
  ASSERT_EQ(a.state(), v1::SESSION_STATE_COMPLETED);
  ASSERT_EQ(b.state(), v1::SESSION_STATE_COMPLETED);
  // One at a time: the second started only after the first had finished.
  auto ra = store_->GetSession(first);
  auto rb = store_->GetSession(second);
  ASSERT_TRUE(ra.ok() && rb.ok());
  ASSERT_TRUE(ra->finished_at.has_value() && rb->started_at.has_value());
  EXPECT_LE(*ra->finished_at, *rb->started_at);
  ExpectIntact(first);
  ExpectIntact(second);
  EXPECT_EQ(manager_->GetRigStatus().active_session_id(), "");

  // ListSessions: newest first, filtered by state.
  auto all = manager_->ListSessions();
  ASSERT_TRUE(all.ok());
  ASSERT_EQ(all->size(), 2u);
  EXPECT_EQ(IdOf((*all)[0]), second);
  EXPECT_FALSE((*all)[0].has_plan());
  auto queued_only = manager_->ListSessions({SessionState::kQueued});
  ASSERT_TRUE(queued_only.ok());
  EXPECT_TRUE(queued_only->empty());
}

TEST_F(EngineTest, ShutdownPausesAfterTheStepInProgressAndClosesTheDevices) {
  const SessionId id = Submit(kSlowPlan);
  Watch(id);
  const auto steps = Steps(id);
  v1::Session s = WaitForSession(*manager_, id, [&steps](const v1::Session& x) {
    return x.state() == v1::SESSION_STATE_RUNNING && x.current_step() >= 0 &&
           steps[static_cast<std::size_t>(x.current_step())].kind == storage::StepKind::kSample;
  });
  ASSERT_EQ(s.state(), v1::SESSION_STATE_RUNNING);
  const int step = s.current_step();
  std::this_thread::sleep_for(100ms);  // inside the reading
  manager_->Shutdown(10s);
  // Deferred: the reading in progress was finished and committed, then the session paused.
  auto record = store_->GetSession(id);
  ASSERT_TRUE(record.ok());
  EXPECT_EQ(record->state, SessionState::kPaused);
  EXPECT_NE(record->state_reason.find("shutting down"), std::string::npos);
  EXPECT_EQ(Steps(id)[static_cast<std::size_t>(step)].state, storage::StepState::kDone);
  ExpectIntact(id);
  const daemon::RigStatus rig = rig_->GetStatus();
  EXPECT_EQ(rig.meter.connection, daemon::DeviceConnection::kDisconnected);
  EXPECT_EQ(rig.stage.connection, daemon::DeviceConnection::kDisconnected);
  EXPECT_EQ(manager_->Resume(id, kTestOperator).status().code(), StatusCode::kFailedPrecondition);
}

TEST_F(EngineTest, InvalidPlanIsRefusedWithEveryProblemAndItsFieldPath) {
  v1::Plan plan = PlanFromJson(R"({
    "name": "bad",
    "sampleRotation": {"alpha": {"start": 0, "stop": 20, "step": -10}, "delta": {"step": 0}}
  })");
  std::vector<plan::Problem> problems;
  auto refused = manager_->SubmitPlan(plan, kTestOperator, false, &problems);
  EXPECT_EQ(refused.status().code(), StatusCode::kInvalidArgument);
  ASSERT_GE(problems.size(), 2u);
  bool alpha = false, delta = false;
  for (const auto& p : problems) {
    alpha |= p.field_path == "sampleRotation.alpha.step";
    delta |= p.field_path == "sampleRotation.delta.step";
    EXPECT_NE(refused.status().message().find(p.field_path), std::string::npos);
  }
  EXPECT_TRUE(alpha && delta);
  EXPECT_FALSE(manager_->ValidatePlan(plan).valid());
  auto listed = manager_->ListSessions();
  ASSERT_TRUE(listed.ok());
  EXPECT_TRUE(listed->empty());  // nothing stored
  EXPECT_EQ(manager_->GetSession(12345).status().code(), StatusCode::kNotFound);
  EXPECT_EQ(manager_->Pause(12345, PauseMode::kDeferred, kTestOperator).status().code(),
            StatusCode::kNotFound);
}

// Without an uncertainty model (Options::uncertainty_model unset) the daemon cannot choose rounds:
// adaptive plans validate, but are neither stored nor started. (With one:
// adaptive_session_test.cc.)
TEST_F(EngineTest, AdaptivePlanValidatesButIsRefusedWithoutAnUncertaintyModel) {
  const v1::Plan plan = PlanFromJson(R"({
    "name": "adaptive",
    "adaptive": {"target": {"expandedUncertainty": 0.05}, "budget": {"maxReadings": 300},
                 "delta": {"start": 0, "stop": 22.5, "step": 11.25}}
  })");
  const plan::PlanAnalysis analysis = manager_->ValidatePlan(plan);
  EXPECT_TRUE(analysis.valid()) << plan::FormatProblems(analysis.problems);
  EXPECT_GT(analysis.summary.sample_readings, 0);  // the seed design's cost
  for (bool start_now : {true, false}) {
    auto refused = manager_->SubmitPlan(plan, kTestOperator, start_now);
    EXPECT_EQ(refused.status().code(), StatusCode::kFailedPrecondition);
    EXPECT_EQ(refused.status().message(),
              "no uncertainty model is configured in this daemon, so it cannot choose the rounds "
              "of an adaptive plan (it validates and estimates); run the plan on a daemon that "
              "has one");
  }
  auto listed = manager_->ListSessions();
  ASSERT_TRUE(listed.ok());
  EXPECT_TRUE(listed->empty());  // nothing stored, nothing queued
  // A stored adaptive session (another daemon's, say) is not started either.
  storage::NewSession stored;
  stored.name = "adaptive";
  stored.plan_kind = "adaptive";
  Result<std::string> json = plan::PlanToJson(plan);
  ASSERT_TRUE(json.ok());
  stored.plan_json = *json;
  std::vector<storage::StepRecord> seed;
  for (const plan::Step& step : analysis.steps) seed.push_back(daemon::ToStepRecord(step));
  Result<std::int64_t> id = store_->CreateSession(stored, seed);
  ASSERT_TRUE(id.ok()) << id.status().ToString();
  auto start = manager_->Start(*id, kTestOperator);
  EXPECT_EQ(start.status().code(), StatusCode::kFailedPrecondition);
  EXPECT_NE(start.status().message().find("no uncertainty model is configured"), std::string::npos);
  auto session = manager_->GetSession(*id);
  ASSERT_TRUE(session.ok());
  EXPECT_EQ(session->state(), v1::SESSION_STATE_QUEUED);
}

TEST_F(EngineTest, RigReportsBothDevicesTheMeterSerialAndTheLivePose) {
  v1::RigStatus status;
  const auto until = std::chrono::steady_clock::now() + 10s;
  while (std::chrono::steady_clock::now() < until) {
    status = manager_->GetRigStatus();
    if (status.devices_size() == 2 && status.devices(0).state() == v1::CONNECTION_STATE_CONNECTED &&
        status.devices(1).state() == v1::CONNECTION_STATE_CONNECTED && status.live_pose_valid()) {
      break;
    }
    std::this_thread::sleep_for(20ms);
  }
  ASSERT_EQ(status.devices_size(), 2);
  EXPECT_EQ(status.devices(0).name(), "meter");
  EXPECT_EQ(status.devices(0).state(), v1::CONNECTION_STATE_CONNECTED);
  EXPECT_EQ(status.devices(1).name(), "stage");
  EXPECT_EQ(status.devices(1).state(), v1::CONNECTION_STATE_CONNECTED);
  EXPECT_FALSE(status.meter_serial().empty());
  EXPECT_TRUE(status.live_pose_valid());
  EXPECT_TRUE(status.detector_arm_motorized());
  ASSERT_TRUE(rig_->GetStatus().meter_grid.has_value());
  EXPECT_GT(rig_->GetStatus().meter_grid->count, 0);
}

// Without devices the daemon still works: the rig shows disconnected and keeps retrying, plans
// are accepted, and a session that needs the rig pauses with the reason instead of crashing.
TEST(EngineWithoutDevicesTest, RigIsRetriedAndASessionPausesWithTheReason) {
  TempDir dir("brdf-engine-nodev");
  auto store = storage::SessionStore::Open(dir.file("brdfd.db").string());
  ASSERT_TRUE(store.ok()) << store.status().ToString();
  auto free_port = FreeTcpPort();
  ASSERT_TRUE(free_port.ok());
  drivers::Pr650Options meter;
  meter.port = (dir.path() / "no-such-port").string();
  meter.log = [](std::string_view) {};
  drivers::stage::ModbusStageConfig stage_config;
  drivers::stage::BusConfig bus;
  bus.endpoint = drivers::stage::TcpEndpoint{"127.0.0.1", *free_port};
  bus.response_timeout = 100ms;
  bus.reconnect_attempts = 1;
  bus.reconnect_backoff = 10ms;
  stage_config.buses = {bus};
  stage_config.axes[0] = {true, 0, 1, 10000.0 / 360.0, 0, 0, 90, 30};
  stage_config.axes[1] = {true, 0, 2, 10000.0 / 360.0, 0, -180, 180, 30};
  auto stage = drivers::stage::ModbusStage::Create(stage_config);
  ASSERT_TRUE(stage.ok()) << stage.status().ToString();
  daemon::Rig::Options rig_options;
  rig_options.backoff_initial = 20ms;
  rig_options.backoff_max = 100ms;
  rig_options.connect_timeout = 500ms;
  plan::RigDescription description = SimRigDescription();
  description.has_detector_arm = false;
  auto rig = std::make_shared<daemon::Rig>(
      std::make_unique<drivers::Pr650Spectroradiometer>(meter),
      daemon::Rig::DeviceInfo{"PR-650", meter.port}, std::move(*stage),
      daemon::Rig::DeviceInfo{"stage", "127.0.0.1"}, description, rig_options);
  daemon::SessionManager::Options options = ManagerOptions();
  options.rig_description = description;
  daemon::SessionManager manager(std::move(*store), rig, options);

  // Retried: the failed attempts keep counting up.
  const auto until = std::chrono::steady_clock::now() + 5s;
  while (std::chrono::steady_clock::now() < until && rig->GetStatus().stage.failed_attempts < 3) {
    std::this_thread::sleep_for(10ms);
  }
  const daemon::RigStatus status = rig->GetStatus();
  EXPECT_GE(status.stage.failed_attempts, 3);
  EXPECT_GE(status.meter.failed_attempts, 1);
  EXPECT_EQ(status.meter.connection, daemon::DeviceConnection::kDisconnected);
  EXPECT_EQ(status.stage.connection, daemon::DeviceConnection::kDisconnected);
  EXPECT_FALSE(status.stage.last_error.empty());
  EXPECT_FALSE(status.live_pose.has_value());

  auto s = manager.SubmitPlan(PlanFromJson(kTinyPlan), kTestOperator, true);
  ASSERT_TRUE(s.ok()) << s.status().ToString();
  const SessionId id = IdOf(*s);
  // The first step is a prompt; answer it so that the rig is needed.
  v1::Session paused = WaitForSession(manager, id, [&](const v1::Session& x) {
    if (x.state() == v1::SESSION_STATE_AWAITING_OPERATOR) {
      (void)manager.AnswerPrompt(id, x.pending_prompt().step_index(), "", kTestOperator);
    }
    return x.state() == v1::SESSION_STATE_PAUSED;
  });
  ASSERT_EQ(paused.state(), v1::SESSION_STATE_PAUSED);
  ASSERT_TRUE(paused.has_last_fault());
  EXPECT_FALSE(paused.last_fault().reason().empty());
  manager.Shutdown(2s);
}

}  // namespace
}  // namespace brdf::testing
