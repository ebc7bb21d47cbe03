// SessionStore's contract with the daemon: round trips, one-transaction writes, no duplicates,
// state rules, recovery after a restart, streaming readings, devices, audit, and the checker.
#include "storage/session_store.h"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <atomic>
#include <cstring>

#include "storage_test_util.h"

namespace brdf::storage {
namespace {

using ::testing::ElementsAre;
using ::testing::HasSubstr;
using testing::KindOfStep;
using testing::MakeNewSession;
using testing::MakeReading;
using testing::MakeSteps;
using ::testing::Not;
using testing::ReadingKindOfStep;
using testing::TempDir;

constexpr UnixSeconds kEpoch = 1.7e9;

class SessionStoreTest : public ::testing::Test {
 protected:
  void SetUp() override {
    SessionStore::Options options;
    options.wall_clock = [this] { return kEpoch + ticks_.fetch_add(1); };
    auto store = SessionStore::Open(path(), options);
    ASSERT_TRUE(store.ok()) << store.status().ToString();
    store_ = std::move(store).value();
  }

  std::string path() const { return dir_.File("brdfd.db"); }

  // A second, plain connection to the same file: what the test sees independently of the store.
  std::unique_ptr<Database> Raw() {
    auto db = Database::Open(path());
    EXPECT_TRUE(db.ok()) << db.status().ToString();
    return std::move(db).value();
  }

  std::int64_t NewRunningSession(int steps) {
    auto id = store_->CreateSession(MakeNewSession(), MakeSteps(steps));
    EXPECT_TRUE(id.ok()) << id.status().ToString();
    EXPECT_TRUE(store_->SetSessionState(*id, SessionState::kRunning, "operator started").ok());
    return *id;
  }

  // Completes step i of the standard plan the way the daemon would.
  Status Complete(std::int64_t session, int i) {
    if (KindOfStep(i) == StepKind::kMove) return store_->CompleteStep(session, i);
    return store_->CompleteStepWithReading(session, i, MakeReading(i, ReadingKindOfStep(i)))
        .status();
  }

  void ExpectClean(std::int64_t session) {
    auto report = store_->CheckSession(session);
    ASSERT_TRUE(report.ok()) << report.status().ToString();
    EXPECT_TRUE(report->ok()) << report->Summary();
  }

  TempDir dir_;
  std::atomic<int> ticks_{0};
  std::unique_ptr<SessionStore> store_;
};

TEST_F(SessionStoreTest, CreateSessionStoresTheSessionAndAllItsSteps) {
  NewSession in = MakeNewSession("wood, varnished");
  std::vector<StepRecord> steps = MakeSteps(25);
  steps[7].kind = StepKind::kPrompt;
  steps[7].prompt = "Mount the white standard, then confirm.";
  steps[7].prompt_kind = "mount_white";
  steps[7].expected_action = "white standard mounted";
  steps[7].target.reset();
  auto id = store_->CreateSession(in, steps);
  ASSERT_TRUE(id.ok()) << id.status().ToString();

  auto s = store_->GetSession(*id);
  ASSERT_TRUE(s.ok()) << s.status().ToString();
  EXPECT_EQ(s->id, *id);
  EXPECT_EQ(s->name, "wood, varnished");
  EXPECT_EQ(s->plan_kind, in.plan_kind);
  EXPECT_EQ(s->plan_json, in.plan_json);
  EXPECT_EQ(s->state, SessionState::kQueued);
  EXPECT_EQ(s->state_reason, "");
  EXPECT_EQ(s->created_at, kEpoch);
  EXPECT_EQ(s->started_at, std::nullopt);
  EXPECT_EQ(s->finished_at, std::nullopt);
  EXPECT_EQ(s->created_by_role, "operator");
  EXPECT_EQ(s->total_steps, 25);
  EXPECT_EQ(s->done_steps, 0);
  EXPECT_EQ(s->white_reflectance, 0.99);
  EXPECT_EQ(s->meter_serial, "60954201");
  EXPECT_EQ(s->config_json, in.config_json);

  auto got = store_->GetSteps(*id);
  ASSERT_TRUE(got.ok()) << got.status().ToString();
  ASSERT_EQ(got->size(), steps.size());
  for (std::size_t i = 0; i < steps.size(); ++i) {
    const StepRecord& g = (*got)[i];
    EXPECT_EQ(g.session_id, *id);
    EXPECT_EQ(g.step_index, steps[i].step_index);
    EXPECT_EQ(g.kind, steps[i].kind);
    EXPECT_EQ(g.pose, steps[i].pose);
    EXPECT_EQ(g.prompt, steps[i].prompt);
    EXPECT_EQ(g.prompt_kind, steps[i].prompt_kind);
    EXPECT_EQ(g.expected_action, steps[i].expected_action);
    EXPECT_EQ(g.target, steps[i].target);
    EXPECT_EQ(g.label, steps[i].label);
    EXPECT_EQ(g.state, StepState::kPending);
    EXPECT_EQ(g.completed_at, std::nullopt);
  }
  EXPECT_EQ(*store_->FirstUnfinishedStep(*id), 0);
  ExpectClean(*id);
}

TEST_F(SessionStoreTest, MisnumberedOrEmptyPlansAreRefusedAndNothingIsStored) {
  std::vector<StepRecord> steps = MakeSteps(5);
  steps[3].step_index = 4;
  auto bad = store_->CreateSession(MakeNewSession(), steps);
  ASSERT_FALSE(bad.ok());
  EXPECT_EQ(bad.status().code(), StatusCode::kInvalidArgument);
  EXPECT_THAT(bad.status().message(), HasSubstr("step 3 has step_index 4"));
  auto empty = store_->CreateSession(MakeNewSession(), {});
  EXPECT_EQ(empty.status().code(), StatusCode::kInvalidArgument);
  EXPECT_TRUE(store_->ListSessions()->empty());
}

TEST_F(SessionStoreTest, SessionAndStepsAreCreatedInOneTransaction) {
  // Make the database refuse step 40 of the plan: the session before it must not persist either.
  ASSERT_TRUE(Raw()
                  ->Exec("CREATE TRIGGER refuse_step BEFORE INSERT ON steps "
                         "WHEN NEW.step_index = 40 BEGIN "
                         "SELECT RAISE(ABORT, 'simulated failure while storing the plan'); END")
                  .ok());
  auto id = store_->CreateSession(MakeNewSession(), MakeSteps(60));
  ASSERT_FALSE(id.ok());
  EXPECT_THAT(id.status().message(), HasSubstr("simulated failure while storing the plan"));
  EXPECT_THAT(id.status().message(), HasSubstr("step 40"));
  auto raw = Raw();
  EXPECT_EQ(*raw->QueryInt64("SELECT count(*) FROM sessions"), 0);
  EXPECT_EQ(*raw->QueryInt64("SELECT count(*) FROM steps"), 0);
  ASSERT_TRUE(raw->Exec("DROP TRIGGER refuse_step").ok());
  EXPECT_TRUE(store_->CreateSession(MakeNewSession(), MakeSteps(60)).ok());
}

TEST_F(SessionStoreTest, ReadingRoundTripsWithItsSpectrumBitExact) {
  const std::int64_t session = NewRunningSession(12);
  // A PR-670's grid, for the reference too: a session keeps one grid.
  const WavelengthGrid pr670{380, 2, 201};
  auto ref =
      store_->CompleteStepWithReading(session, 1, MakeReading(1, ReadingKind::kReference, pr670));
  ASSERT_TRUE(ref.ok()) << ref.status().ToString();

  ReadingRecord in = MakeReading(2, ReadingKind::kSample, pr670);
  in.spectrum[0] = -0.0;
  in.spectrum[1] = std::numeric_limits<double>::denorm_min();
  in.spectrum[2] = 1.0 / 3.0;
  in.reference_reading_id = *ref;
  in.recorded_at = 1.75e9 + 0.125;
  auto id = store_->CompleteStepWithReading(session, 2, in);
  ASSERT_TRUE(id.ok()) << id.status().ToString();

  auto out = store_->GetReading(*id);
  ASSERT_TRUE(out.ok()) << out.status().ToString();
  EXPECT_EQ(out->id, *id);
  EXPECT_EQ(out->session_id, session);
  EXPECT_EQ(out->step_index, 2);
  EXPECT_EQ(out->kind, ReadingKind::kSample);
  EXPECT_EQ(out->pose, in.pose);
  EXPECT_EQ(out->directions, in.directions);
  EXPECT_EQ(out->grid, in.grid);
  ASSERT_EQ(out->spectrum.size(), 201u);
  EXPECT_EQ(std::memcmp(out->spectrum.data(), in.spectrum.data(), 201 * sizeof(double)), 0);
  EXPECT_TRUE(std::signbit(out->spectrum[0]));
  EXPECT_EQ(out->quality_code, in.quality_code);
  EXPECT_EQ(out->flagged, in.flagged);
  EXPECT_EQ(out->integration_ms, in.integration_ms);
  EXPECT_EQ(out->attempts, in.attempts);
  EXPECT_EQ(out->note, in.note);
  EXPECT_EQ(out->reference_reading_id, *ref);
  EXPECT_EQ(out->dark_reading_id, std::nullopt);
  EXPECT_EQ(out->meter_serial, in.meter_serial);
  EXPECT_EQ(out->recorded_at, in.recorded_at);

  auto steps = store_->GetSteps(session);
  ASSERT_TRUE(steps.ok());
  EXPECT_EQ((*steps)[2].state, StepState::kDone);
  EXPECT_EQ((*steps)[2].completed_at, in.recorded_at);
  EXPECT_EQ(store_->GetSession(session)->done_steps, 2);
  EXPECT_EQ(*store_->FirstUnfinishedStep(session), 0) << "step 0 (a move) is still pending";
  ExpectClean(session);
}

TEST_F(SessionStoreTest, ReadingAndDoneMarkCommitTogetherOrNotAtAll) {
  const std::int64_t session = NewRunningSession(10);
  // A failure after the reading's INSERT: first when marking the step, then when counting it.
  const char* triggers[] = {
      "CREATE TRIGGER fail_between BEFORE UPDATE OF state ON steps BEGIN "
      "SELECT RAISE(ABORT, 'simulated failure between insert and mark'); END",
      "CREATE TRIGGER fail_between BEFORE UPDATE OF done_steps ON sessions BEGIN "
      "SELECT RAISE(ABORT, 'simulated failure between insert and mark'); END",
  };
  for (const char* trigger : triggers) {
    SCOPED_TRACE(trigger);
    ASSERT_TRUE(Raw()->Exec(trigger).ok());
    auto id = store_->CompleteStepWithReading(session, 2, MakeReading(2, ReadingKind::kSample));
    ASSERT_FALSE(id.ok());
    EXPECT_THAT(id.status().message(), HasSubstr("simulated failure between insert and mark"));
    EXPECT_THAT(id.status().message(), HasSubstr("step 2 of session"));
    auto raw = Raw();
    EXPECT_EQ(*raw->QueryInt64("SELECT count(*) FROM readings"), 0) << "the INSERT was undone";
    EXPECT_EQ(*raw->QueryText("SELECT state FROM steps WHERE step_index = 2"), "pending");
    EXPECT_EQ(*raw->QueryInt64("SELECT done_steps FROM sessions"), 0);
    ExpectClean(session);
    ASSERT_TRUE(raw->Exec("DROP TRIGGER fail_between").ok());
  }
  // The store is not left inside a transaction: the retry succeeds.
  auto id = store_->CompleteStepWithReading(session, 2, MakeReading(2, ReadingKind::kSample));
  ASSERT_TRUE(id.ok()) << id.status().ToString();
  EXPECT_EQ(*store_->CountReadings(session), 1);
  ExpectClean(session);
}

TEST_F(SessionStoreTest, ABadReferenceStoresNothing) {
  const std::int64_t session = NewRunningSession(10);
  const std::int64_t other = NewRunningSession(10);
  auto other_ref =
      store_->CompleteStepWithReading(other, 1, MakeReading(1, ReadingKind::kReference));
  ASSERT_TRUE(other_ref.ok());
  auto own_sample =
      store_->CompleteStepWithReading(session, 3, MakeReading(3, ReadingKind::kSample));
  ASSERT_TRUE(own_sample.ok());

  struct Case {
    std::optional<std::int64_t> reference;
    std::optional<std::int64_t> dark;
    std::string expected;
  };
  const Case cases[] = {
      {9999, std::nullopt, "reference reading 9999 does not exist"},
      {*other_ref, std::nullopt, "belongs to session " + std::to_string(other)},
      {*own_sample, std::nullopt, "is a sample reading, not a reference reading"},
      {std::nullopt, *own_sample, "is a sample reading, not a dark reading"},
  };
  for (const Case& c : cases) {
    ReadingRecord r = MakeReading(2, ReadingKind::kSample);
    r.reference_reading_id = c.reference;
    r.dark_reading_id = c.dark;
    auto id = store_->CompleteStepWithReading(session, 2, r);
    ASSERT_FALSE(id.ok());
    EXPECT_EQ(id.status().code(), StatusCode::kInvalidArgument) << id.status().ToString();
    EXPECT_THAT(id.status().message(), HasSubstr(c.expected));
  }
  EXPECT_EQ(*store_->CountReadings(session), 1);
  EXPECT_EQ(store_->GetSession(session)->done_steps, 1);
  ExpectClean(session);
}

TEST_F(SessionStoreTest, ASecondCompletionOfAStepIsRefusedAndWritesNothing) {
  const std::int64_t session = NewRunningSession(10);
  auto first = store_->CompleteStepWithReading(session, 5, MakeReading(5, ReadingKind::kSample));
  ASSERT_TRUE(first.ok());
  // A retried call (the daemon did not see the first answer), even with different data.
  auto again = store_->CompleteStepWithReading(session, 5, MakeReading(6, ReadingKind::kSample));
  ASSERT_FALSE(again.ok());
  EXPECT_EQ(again.status().code(), StatusCode::kFailedPrecondition);
  EXPECT_THAT(again.status().message(),
              HasSubstr("step 5 of session " + std::to_string(session) + " is already done"));
  EXPECT_THAT(again.status().message(), HasSubstr("(reading " + std::to_string(*first) + ")"));
  ASSERT_TRUE(store_->CompleteStep(session, 0).ok());
  Status move_again = store_->CompleteStep(session, 0);
  EXPECT_EQ(move_again.code(), StatusCode::kFailedPrecondition);
  EXPECT_EQ(*store_->CountReadings(session), 1);
  EXPECT_EQ(store_->GetSession(session)->done_steps, 2);
  EXPECT_EQ(store_->GetReading(*first)->spectrum, MakeReading(5, ReadingKind::kSample).spectrum);
  ExpectClean(session);
}

TEST_F(SessionStoreTest, TheDatabaseItselfForbidsASecondReadingForAStep) {
  const std::int64_t session = NewRunningSession(10);
  ASSERT_TRUE(
      store_->CompleteStepWithReading(session, 2, MakeReading(2, ReadingKind::kSample)).ok());
  // Bypassing the store: a stray second row for the same step.
  Status s = Raw()->Exec(
      "INSERT INTO readings (session_id, step_index, kind, alpha, beta, gamma, delta, theta_i, "
      "phi_i, theta_o, phi_o, wl_start_nm, wl_step_nm, wl_count, spectrum, recorded_at) "
      "SELECT session_id, step_index, kind, alpha, beta, gamma, delta, theta_i, phi_i, theta_o, "
      "phi_o, wl_start_nm, wl_step_nm, wl_count, spectrum, recorded_at FROM readings");
  EXPECT_EQ(s.code(), StatusCode::kFailedPrecondition) << s.ToString();
  EXPECT_THAT(s.message(), HasSubstr("UNIQUE constraint failed: readings.session_id"));
}

TEST_F(SessionStoreTest, AStrayReadingBlocksCompletionAndTheCheckerNamesIt) {
  const std::int64_t session = NewRunningSession(10);
  // A reading row for pending step 4 written behind the store's back.
  ASSERT_TRUE(Raw()
                  ->Exec("INSERT INTO readings (session_id, step_index, kind, alpha, beta, gamma, "
                         "delta, theta_i, phi_i, theta_o, phi_o, wl_start_nm, wl_step_nm, "
                         "wl_count, spectrum, recorded_at) VALUES (" +
                         std::to_string(session) +
                         ", 4, 'sample', 0, 0, 0, 0, 0, 0, 0, 0, 380, 4, 1, zeroblob(8), 0)")
                  .ok());
  auto report = store_->CheckSession(session);
  ASSERT_TRUE(report.ok());
  EXPECT_FALSE(report->ok());
  EXPECT_THAT(report->Summary(), HasSubstr("belong to steps that are not done"));
  // The store refuses to add a second reading, and the step stays pending.
  auto id = store_->CompleteStepWithReading(session, 4, MakeReading(4, ReadingKind::kSample));
  ASSERT_FALSE(id.ok());
  EXPECT_EQ(id.status().code(), StatusCode::kFailedPrecondition) << id.status().ToString();
  EXPECT_EQ((*store_->GetSteps(session))[4].state, StepState::kPending);
  EXPECT_EQ(store_->GetSession(session)->done_steps, 0);
}

TEST_F(SessionStoreTest, StepKindsAndReadingKindsMustAgree) {
  const std::int64_t session = NewRunningSession(10);
  auto on_move = store_->CompleteStepWithReading(session, 0, MakeReading(0, ReadingKind::kSample));
  EXPECT_EQ(on_move.status().code(), StatusCode::kInvalidArgument);
  EXPECT_THAT(on_move.status().message(), HasSubstr("move step, which takes no reading"));
  auto wrong_kind =
      store_->CompleteStepWithReading(session, 1, MakeReading(1, ReadingKind::kSample));
  EXPECT_EQ(wrong_kind.status().code(), StatusCode::kInvalidArgument);
  EXPECT_THAT(wrong_kind.status().message(),
              HasSubstr("reference step but the reading is a sample reading"));
  Status no_reading = store_->CompleteStep(session, 2);
  EXPECT_EQ(no_reading.code(), StatusCode::kInvalidArgument);
  EXPECT_THAT(no_reading.message(), HasSubstr("completes with its reading"));
  ReadingRecord short_spectrum = MakeReading(2, ReadingKind::kSample);
  short_spectrum.spectrum.pop_back();
  auto bad = store_->CompleteStepWithReading(session, 2, short_spectrum);
  EXPECT_EQ(bad.status().code(), StatusCode::kInvalidArgument);
  EXPECT_THAT(bad.status().message(), HasSubstr("100 values but its grid has 101 bands"));
  ReadingRecord nan_pose = MakeReading(2, ReadingKind::kSample);
  nan_pose.pose.beta = std::nan("");
  EXPECT_EQ(store_->CompleteStepWithReading(session, 2, nan_pose).status().code(),
            StatusCode::kInvalidArgument);
  EXPECT_EQ(*store_->CountReadings(session), 0);
  EXPECT_EQ(store_->GetSession(session)->done_steps, 0);
  ExpectClean(session);
}

TEST_F(SessionStoreTest, UnknownSessionsStepsAndReadingsAreNotFoundByName) {
  const std::int64_t session = NewRunningSession(10);
  auto s = store_->GetSession(777);
  EXPECT_EQ(s.status().code(), StatusCode::kNotFound);
  // The daemon's clients see these messages: no server path in them (issue 20).
  EXPECT_THAT(s.status().message(), HasSubstr("no session 777 in the database"));
  EXPECT_THAT(s.status().message(), Not(HasSubstr(path())));
  EXPECT_EQ(store_->GetSteps(777).status().code(), StatusCode::kNotFound);
  EXPECT_EQ(store_->FirstUnfinishedStep(777).status().code(), StatusCode::kNotFound);
  EXPECT_EQ(store_->GetReadings(777, 0, 10).status().code(), StatusCode::kNotFound);
  EXPECT_EQ(store_->CheckSession(777).status().code(), StatusCode::kNotFound);
  EXPECT_EQ(store_->SetSessionState(777, SessionState::kPaused, "").code(), StatusCode::kNotFound);
  auto step = store_->CompleteStepWithReading(session, 10, MakeReading(10, ReadingKind::kSample));
  EXPECT_EQ(step.status().code(), StatusCode::kNotFound);
  EXPECT_THAT(step.status().message(), HasSubstr("plan has 10 steps, numbered 0 to 9"));
  auto reading = store_->GetReading(4242);
  EXPECT_EQ(reading.status().code(), StatusCode::kNotFound);
  EXPECT_THAT(reading.status().message(), HasSubstr("no reading 4242"));
}

TEST_F(SessionStoreTest, StateChangesKeepTimestampsAndRefuseLeavingTheEnd) {
  auto id = store_->CreateSession(MakeNewSession(), MakeSteps(3));
  ASSERT_TRUE(id.ok());
  // Not started: no readings, no completions.
  auto early = store_->CompleteStepWithReading(*id, 1, MakeReading(1, ReadingKind::kReference));
  EXPECT_EQ(early.status().code(), StatusCode::kFailedPrecondition);
  EXPECT_THAT(early.status().message(), HasSubstr("is queued (not started)"));

  ASSERT_TRUE(store_->SetSessionState(*id, SessionState::kRunning, "operator started").ok());
  const auto started = store_->GetSession(*id)->started_at;
  ASSERT_TRUE(started.has_value());
  ASSERT_TRUE(store_->SetSessionState(*id, SessionState::kPaused, "operator paused").ok());
  ASSERT_TRUE(store_->SetSessionState(*id, SessionState::kRunning, "resumed").ok());
  auto s = store_->GetSession(*id);
  EXPECT_EQ(s->started_at, started) << "started_at is the first start";
  EXPECT_EQ(s->state_reason, "resumed");
  EXPECT_EQ(store_->SetSessionState(*id, SessionState::kQueued, "").code(),
            StatusCode::kFailedPrecondition);

  Status too_soon = store_->SetSessionState(*id, SessionState::kCompleted, "");
  EXPECT_EQ(too_soon.code(), StatusCode::kFailedPrecondition);
  EXPECT_THAT(too_soon.message(), HasSubstr("3 steps are still pending (the first is step 0)"));

  ASSERT_TRUE(store_->CompleteStep(*id, 0).ok());
  ASSERT_TRUE(
      store_->CompleteStepWithReading(*id, 1, MakeReading(1, ReadingKind::kReference)).ok());
  ASSERT_TRUE(store_->SkipStep(*id, 2, "pose unreachable: lamp below the horizon").ok());
  ASSERT_TRUE(store_->SetSessionState(*id, SessionState::kCompleted, "all steps done").ok());
  s = store_->GetSession(*id);
  EXPECT_EQ(s->state, SessionState::kCompleted);
  EXPECT_EQ(s->done_steps, 3);
  ASSERT_TRUE(s->finished_at.has_value());
  EXPECT_GT(*s->finished_at, *started);
  EXPECT_EQ((*store_->GetSteps(*id))[2].note, "pose unreachable: lamp below the horizon");
  EXPECT_EQ(*store_->FirstUnfinishedStep(*id), std::nullopt);

  EXPECT_TRUE(store_->SetSessionState(*id, SessionState::kCompleted, "again").ok())
      << "a retried call is harmless";
  Status after = store_->SetSessionState(*id, SessionState::kRunning, "");
  EXPECT_EQ(after.code(), StatusCode::kFailedPrecondition);
  EXPECT_THAT(after.message(), HasSubstr("already completed"));
  EXPECT_EQ(store_->SkipStep(*id, 2, "x").code(), StatusCode::kFailedPrecondition);
  ExpectClean(*id);
}

TEST_F(SessionStoreTest, RecoveryPausesOnlySessionsADeadDaemonWasDriving) {
  std::vector<std::int64_t> ids;
  const SessionState states[] = {SessionState::kQueued,           SessionState::kRunning,
                                 SessionState::kPausing,          SessionState::kPaused,
                                 SessionState::kAwaitingOperator, SessionState::kAborted};
  for (SessionState state : states) {
    auto id = store_->CreateSession(MakeNewSession(std::string(ToString(state))), MakeSteps(3));
    ASSERT_TRUE(id.ok());
    if (state != SessionState::kQueued) {
      ASSERT_TRUE(store_->SetSessionState(*id, SessionState::kRunning, "").ok());
      if (state != SessionState::kRunning) {
        ASSERT_TRUE(store_->SetSessionState(*id, state, "before the crash").ok());
      }
    }
    ids.push_back(*id);
  }
  store_.reset();  // the daemon dies; a new one starts
  auto store = SessionStore::Open(path());
  ASSERT_TRUE(store.ok());
  auto recovered = (*store)->RecoverInterruptedSessions();
  ASSERT_TRUE(recovered.ok()) << recovered.status().ToString();
  EXPECT_THAT(*recovered, ElementsAre(ids[1], ids[2], ids[4]));
  const SessionState after[] = {SessionState::kQueued, SessionState::kPaused,
                                SessionState::kPaused, SessionState::kPaused,
                                SessionState::kPaused, SessionState::kAborted};
  for (std::size_t i = 0; i < ids.size(); ++i) {
    auto s = (*store)->GetSession(ids[i]);
    EXPECT_EQ(s->state, after[i]) << s->name;
    if (i == 1 || i == 2 || i == 4) {
      EXPECT_EQ(s->state_reason, kRecoveredReason);
    } else {
      EXPECT_NE(s->state_reason, kRecoveredReason);
    }
  }
  EXPECT_TRUE((*store)->RecoverInterruptedSessions()->empty());
}

TEST_F(SessionStoreTest, ReadingsStreamInPagesAndForEachVisitsEveryOneOnce) {
  const std::int64_t session = NewRunningSession(300);
  const std::int64_t other = NewRunningSession(20);
  int expected = 0;
  for (int i = 0; i < 300; ++i) {
    ASSERT_TRUE(Complete(session, i).ok()) << i;
    if (KindOfStep(i) != StepKind::kMove) ++expected;
    if (i < 20) {
      ASSERT_TRUE(Complete(other, i).ok());
    }
  }
  ASSERT_GT(expected, 256) << "must cross ForEachReading's page size";
  EXPECT_EQ(*store_->CountReadings(session), expected);

  std::int64_t after = 0;
  int seen = 0;
  while (true) {
    auto page = store_->GetReadings(session, after, 37);
    ASSERT_TRUE(page.ok()) << page.status().ToString();
    if (page->empty()) break;
    EXPECT_LE(page->size(), 37u);
    for (const ReadingRecord& r : *page) {
      EXPECT_GT(r.id, after);
      EXPECT_EQ(r.session_id, session);
      EXPECT_EQ(r.spectrum, MakeReading(r.step_index, r.kind).spectrum);
      after = r.id;
      ++seen;
    }
  }
  EXPECT_EQ(seen, expected);

  // GetReadingPoints pages the same readings, each where it was taken, without its spectrum.
  after = 0;
  seen = 0;
  while (true) {
    auto points = store_->GetReadingPoints(session, after, 41);
    ASSERT_TRUE(points.ok()) << points.status().ToString();
    if (points->empty()) break;
    auto readings = store_->GetReadings(session, after, 41);
    ASSERT_TRUE(readings.ok());
    ASSERT_EQ(points->size(), readings->size());
    for (std::size_t i = 0; i < points->size(); ++i) {
      const ReadingPointRecord& p = (*points)[i];
      const ReadingRecord& r = (*readings)[i];
      EXPECT_EQ(p.id, r.id);
      EXPECT_EQ(p.kind, r.kind);
      EXPECT_EQ(p.pose, r.pose);
      EXPECT_EQ(p.directions, r.directions);
      EXPECT_EQ(p.flagged, r.flagged);
      after = p.id;
      ++seen;
    }
  }
  EXPECT_EQ(seen, expected);
  EXPECT_EQ(store_->GetReadingPoints(777, 0, 10).status().code(), StatusCode::kNotFound);
  EXPECT_EQ(store_->GetReadingPoints(session, 0, 0).status().code(), StatusCode::kInvalidArgument);

  std::vector<int> steps;
  ASSERT_TRUE(store_
                  ->ForEachReading(session,
                                   [&](const ReadingRecord& r) {
                                     steps.push_back(r.step_index);
                                     return Status::Ok();
                                   })
                  .ok());
  ASSERT_EQ(static_cast<int>(steps.size()), expected);
  for (std::size_t i = 1; i < steps.size(); ++i) ASSERT_LT(steps[i - 1], steps[i]);

  int visited = 0;
  Status stop = store_->ForEachReading(session, [&](const ReadingRecord&) {
    return ++visited == 5 ? Cancelled("client went away") : Status::Ok();
  });
  EXPECT_EQ(stop.code(), StatusCode::kCancelled);
  EXPECT_EQ(visited, 5);
  EXPECT_EQ(store_->GetReadings(session, 0, 0).status().code(), StatusCode::kInvalidArgument);
  ExpectClean(session);
  ExpectClean(other);
}

TEST_F(SessionStoreTest, DevicesAreRecordedOncePerSession) {
  const std::int64_t session = NewRunningSession(3);
  DeviceRecord meter{0, session, "spectroradiometer", "PR-650", "60954201", 0};
  ASSERT_TRUE(store_->RecordDevice(meter).ok());
  meter.first_seen = kEpoch + 1000;
  ASSERT_TRUE(store_->RecordDevice(meter).ok());  // seen again: first_seen stays
  DeviceRecord daemon_level{0, std::nullopt, "spectroradiometer", "PR-650", "60954201", 0};
  ASSERT_TRUE(store_->RecordDevice(daemon_level).ok());
  ASSERT_TRUE(store_->RecordDevice(daemon_level).ok());
  ASSERT_TRUE(store_->RecordDevice({0, session, "rotation_stage", "SC300", "A17", 0}).ok());
  EXPECT_EQ(store_->RecordDevice({0, 4242, "rotation_stage", "SC300", "A17", 0}).code(),
            StatusCode::kInvalidArgument);

  auto all = store_->GetDevices(std::nullopt);
  ASSERT_TRUE(all.ok());
  EXPECT_EQ(all->size(), 3u);
  auto mine = store_->GetDevices(session);
  ASSERT_TRUE(mine.ok());
  ASSERT_EQ(mine->size(), 2u);
  EXPECT_EQ((*mine)[0].serial, "60954201");
  EXPECT_LT((*mine)[0].first_seen, kEpoch + 1000);
  EXPECT_EQ((*mine)[1].kind, "rotation_stage");
  // The same through the SessionReader interface (the BiRD export's meter model).
  SessionReader& reader = *store_;
  auto through_reader = reader.GetSessionDevices(session);
  ASSERT_TRUE(through_reader.ok());
  ASSERT_EQ(through_reader->size(), 2u);
  EXPECT_EQ((*through_reader)[0].model, "PR-650");
}

TEST_F(SessionStoreTest, AuditIsReturnedNewestFirst) {
  const std::int64_t session = NewRunningSession(3);
  ASSERT_TRUE(
      store_->AppendAudit({0, 0, "admin", "lab-pc-2", "daemon.start", std::nullopt, ""}).ok());
  for (int i = 0; i < 5; ++i) {
    ASSERT_TRUE(store_
                    ->AppendAudit({0, 0, "operator", "lab-pc-1", "session.pause", session,
                                   "pause " + std::to_string(i)})
                    .ok());
  }
  auto last3 = store_->GetAudit(session, 3);
  ASSERT_TRUE(last3.ok());
  ASSERT_EQ(last3->size(), 3u);
  EXPECT_EQ((*last3)[0].detail, "pause 4");
  EXPECT_EQ((*last3)[2].detail, "pause 2");
  EXPECT_EQ((*last3)[0].actor, "lab-pc-1");
  EXPECT_EQ((*last3)[0].session_id, session);
  EXPECT_GT((*last3)[0].at, (*last3)[2].at);
  auto all = store_->GetAudit(std::nullopt, 100);
  ASSERT_EQ(all->size(), 6u);
  EXPECT_EQ(all->back().action, "daemon.start");
  EXPECT_EQ(all->back().session_id, std::nullopt);
  EXPECT_EQ(store_->AppendAudit({0, 0, "operator", "", "session.pause", session, ""}).code(),
            StatusCode::kInvalidArgument);
  EXPECT_EQ(store_->AppendAudit({0, 0, "operator", "x", "session.pause", 4242, ""}).code(),
            StatusCode::kInvalidArgument);
  EXPECT_EQ(store_->GetAudit(std::nullopt, 0).status().code(), StatusCode::kInvalidArgument);
}

TEST_F(SessionStoreTest, CheckerFindsDamageDoneBehindTheStoresBack) {
  const std::int64_t session = NewRunningSession(12);
  for (int i = 0; i < 6; ++i) ASSERT_TRUE(Complete(session, i).ok());
  ExpectClean(session);
  auto raw = Raw();
  ASSERT_TRUE(raw->Exec("PRAGMA foreign_keys = OFF;"
                        "UPDATE sessions SET done_steps = 9;"
                        "UPDATE steps SET state = 'done' WHERE step_index = 8;"
                        "DELETE FROM readings WHERE step_index = 3;"
                        "UPDATE readings SET kind = 'dark' WHERE step_index = 4;"
                        "DELETE FROM steps WHERE step_index = 5;")
                  .ok());
  auto report = store_->CheckSession(session);
  ASSERT_TRUE(report.ok()) << report.status().ToString();
  EXPECT_FALSE(report->ok());
  const std::string summary = report->Summary();
  EXPECT_THAT(summary, HasSubstr("the plan has 12 steps but 11 are stored"));
  EXPECT_THAT(summary, HasSubstr("done_steps says 9"));
  EXPECT_THAT(summary, HasSubstr("steps 3, 8 are done but have no reading"));
  EXPECT_THAT(summary, HasSubstr("are of another kind than their step"));
  EXPECT_THAT(summary, HasSubstr("have no step"));
  EXPECT_THAT(summary, HasSubstr("foreign_key_check"));
  EXPECT_EQ(report->integrity_check, "ok");
}

}  // namespace
}  // namespace brdf::storage
