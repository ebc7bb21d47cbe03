// A session's history of states (schema v4): the database's triggers record one event when a
// session is submitted and one per change of its state or reason -- from the store, from start-up
// recovery, or from a hand-run UPDATE -- a v3 file gains one event per session, and events ship
// by id above their mark.
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <atomic>
#include <string>
#include <vector>

#include "storage/schema.h"
#include "storage/session_store.h"
#include "storage_test_util.h"

namespace brdf::storage {
namespace {

using ::testing::ElementsAre;
using testing::KindOfStep;
using testing::MakeNewSession;
using testing::MakeReading;
using testing::MakeSteps;
using testing::ReadingKindOfStep;
using testing::TempDir;

constexpr UnixSeconds kEpoch = 1.7e9;

struct Event {
  SessionState state;
  std::string reason;
  UnixSeconds at;
  bool operator==(const Event&) const = default;
};

void PrintTo(const Event& e, std::ostream* os) {
  *os << "{" << ToString(e.state) << ", \"" << e.reason << "\", " << std::fixed << e.at << "}";
}

std::vector<Event> EventsOf(SessionReader& reader, std::int64_t session) {
  auto events = reader.ListSessionEvents(session);
  EXPECT_TRUE(events.ok()) << events.status().ToString();
  std::vector<Event> out;
  if (!events.ok()) return out;
  std::int64_t last = 0;
  for (const SessionEventRecord& e : *events) {
    EXPECT_EQ(e.session_id, session);
    EXPECT_GT(e.id, last) << "events come in id order";
    last = e.id;
    out.push_back({e.state, e.reason, e.at});
  }
  return out;
}

class SessionEventsTest : public ::testing::Test {
 protected:
  void SetUp() override { Open(); }

  void Open() {
    SessionStore::Options options;
    options.wall_clock = [this] { return kEpoch + ticks_.fetch_add(1); };
    auto store = SessionStore::Open(dir_.File("brdfd.db"), options);
    ASSERT_TRUE(store.ok()) << store.status().ToString();
    store_ = std::move(store).value();
  }

  Status Complete(std::int64_t session, int i) {
    if (KindOfStep(i) == StepKind::kMove) return store_->CompleteStep(session, i);
    return store_->CompleteStepWithReading(session, i, MakeReading(i, ReadingKindOfStep(i)))
        .status();
  }

  TempDir dir_;
  std::atomic<int> ticks_{0};
  std::unique_ptr<SessionStore> store_;
};

TEST_F(SessionEventsTest, SubmitStartPauseResumeCompleteEachLeaveOneEventAtTheStoresTime) {
  auto id = store_->CreateSession(MakeNewSession(), MakeSteps(3));
  ASSERT_TRUE(id.ok()) << id.status().ToString();
  auto created = store_->GetSession(*id);
  ASSERT_TRUE(created.ok());
  const UnixSeconds t0 = created->created_at;

  ASSERT_TRUE(store_->SetSessionState(*id, SessionState::kRunning, "operator started").ok());
  const UnixSeconds t_start = *store_->GetSession(*id)->started_at;
  ASSERT_TRUE(store_->SetSessionState(*id, SessionState::kPausing, "operator paused").ok());
  ASSERT_TRUE(store_->SetSessionState(*id, SessionState::kPaused, "operator paused").ok());
  // Nothing changed: no event.
  ASSERT_TRUE(store_->SetSessionState(*id, SessionState::kPaused, "operator paused").ok());
  ASSERT_TRUE(store_->SetSessionState(*id, SessionState::kRunning, "operator resumed").ok());
  for (int i = 0; i < 3; ++i) ASSERT_TRUE(Complete(*id, i).ok());
  ASSERT_TRUE(store_->SetSessionState(*id, SessionState::kCompleted, "all steps done").ok());
  const UnixSeconds t_end = *store_->GetSession(*id)->finished_at;
  // Retried on a finished session: refused or a no-op, no event either way.
  ASSERT_TRUE(store_->SetSessionState(*id, SessionState::kCompleted, "again").ok());

  const std::vector<Event> events = EventsOf(*store_, *id);
  ASSERT_EQ(events.size(), 6u);
  EXPECT_EQ(events[0], (Event{SessionState::kQueued, "", t0}));
  EXPECT_EQ(events[1], (Event{SessionState::kRunning, "operator started", t_start}));
  EXPECT_EQ(events[2].state, SessionState::kPausing);
  EXPECT_EQ(events[3].state, SessionState::kPaused);
  EXPECT_EQ(events[4], (Event{SessionState::kRunning, "operator resumed", events[4].at}));
  EXPECT_EQ(events[5], (Event{SessionState::kCompleted, "all steps done", t_end}));
  for (std::size_t i = 1; i < events.size(); ++i) {
    EXPECT_GT(events[i].at, events[i - 1].at) << "the store's clock ticks once per call";
  }

  // Another session's events are its own; an unknown session is kNotFound.
  auto other = store_->CreateSession(MakeNewSession("other"), MakeSteps(2));
  ASSERT_TRUE(other.ok());
  EXPECT_EQ(EventsOf(*store_, *other).size(), 1u);
  EXPECT_EQ(EventsOf(*store_, *id).size(), 6u);
  EXPECT_EQ(store_->ListSessionEvents(*other + 100).status().code(), StatusCode::kNotFound);
}

TEST_F(SessionEventsTest, RecoveredSessionGetsAPausedEventWithItsReason) {
  auto id = store_->CreateSession(MakeNewSession(), MakeSteps(3));
  ASSERT_TRUE(id.ok());
  ASSERT_TRUE(store_->SetSessionState(*id, SessionState::kRunning, "").ok());
  store_.reset();  // the daemon dies; a new one starts
  Open();
  auto recovered = store_->RecoverInterruptedSessions();
  ASSERT_TRUE(recovered.ok()) << recovered.status().ToString();
  ASSERT_THAT(*recovered, ElementsAre(*id));
  const std::vector<Event> events = EventsOf(*store_, *id);
  ASSERT_EQ(events.size(), 3u);
  EXPECT_EQ(events[2].state, SessionState::kPaused);
  EXPECT_EQ(events[2].reason, kRecoveredReason);
  EXPECT_GE(events[2].at, kEpoch);  // the store's clock (restarted with the new store)
  EXPECT_LT(events[2].at, kEpoch + 10);
}

TEST_F(SessionEventsTest, AChangeMadeOutsideBrdfdIsRecordedAtSqlitesClock) {
  auto id = store_->CreateSession(MakeNewSession(), MakeSteps(1));
  ASSERT_TRUE(id.ok());
  auto raw = Database::Open(dir_.File("brdfd.db"));
  ASSERT_TRUE(raw.ok());
  ASSERT_TRUE((*raw)
                  ->Exec("UPDATE sessions SET state = 'aborted', state_reason = 'by hand' "
                         "WHERE id = " +
                         std::to_string(*id))
                  .ok());
  ASSERT_TRUE((*raw)->Exec("UPDATE sessions SET name = 'renamed'").ok());  // not a state change
  const std::vector<Event> events = EventsOf(*store_, *id);
  ASSERT_EQ(events.size(), 2u);
  EXPECT_EQ(events[1].state, SessionState::kAborted);
  EXPECT_EQ(events[1].reason, "by hand");
  const double now = static_cast<double>(std::time(nullptr));
  EXPECT_NEAR(events[1].at, now, 60.0);
}

// A file written by a brdfd of schema version 3: each session gets one event (its current state
// and reason, at its last known time), the 'events' mark starts at 0, and later changes append.
TEST(SessionEventsMigrationTest, Version3FileGetsOneEventPerSessionAndAnEventsMark) {
  TempDir dir;
  const std::string path = dir.File("v3.db");
  {
    auto db = Database::Open(path);
    ASSERT_TRUE(db.ok());
    ASSERT_TRUE(Migrate(**db, SchemaMigrations().first(3)).ok());
    ASSERT_TRUE((*db)
                    ->Exec("INSERT INTO sessions (name, plan_kind, plan_json, state, state_reason, "
                           "created_at, started_at, finished_at, total_steps, uuid) VALUES "
                           "('queued', 'pose_list', '{}', 'queued', '', 10.0, NULL, NULL, 0, 'u1'),"
                           "('paused', 'pose_list', '{}', 'paused', 'operator paused', 20.0, 21.0, "
                           "NULL, 0, 'u2'),"
                           "('failed', 'pose_list', '{}', 'failed', 'meter lost', 30.0, 31.0, "
                           "32.5, 0, 'u3')")
                    .ok());
  }
  SessionStore::Options options;
  options.wall_clock = [] { return kEpoch; };
  auto store = SessionStore::Open(path, options);
  ASSERT_TRUE(store.ok()) << store.status().ToString();
  auto sessions = (*store)->ListSessions();
  ASSERT_TRUE(sessions.ok());
  ASSERT_EQ(sessions->size(), 3u);
  EXPECT_THAT(EventsOf(**store, (*sessions)[0].id),
              ElementsAre(Event{SessionState::kQueued, "", 10.0}));
  EXPECT_THAT(EventsOf(**store, (*sessions)[1].id),
              ElementsAre(Event{SessionState::kPaused, "operator paused", 21.0}));
  EXPECT_THAT(EventsOf(**store, (*sessions)[2].id),
              ElementsAre(Event{SessionState::kFailed, "meter lost", 32.5}));

  ASSERT_TRUE((*store)
                  ->SetSessionState((*sessions)[1].id, SessionState::kRunning, "operator resumed")
                  .ok());
  EXPECT_THAT(EventsOf(**store, (*sessions)[1].id),
              ElementsAre(Event{SessionState::kPaused, "operator paused", 21.0},
                          Event{SessionState::kRunning, "operator resumed", kEpoch}));

  auto raw = Database::Open(path);
  ASSERT_TRUE(raw.ok());
  EXPECT_EQ(*SchemaVersion(**raw), LatestSchemaVersion());
  EXPECT_EQ(*(*raw)->QueryInt64("SELECT value FROM archive_marks WHERE name = 'events'"), 0);
}

// Events ship by id above the 'events' mark with the uuids of their sessions; once shipped they
// are not sent again.
TEST_F(SessionEventsTest, EventsShipAboveTheirMark) {
  ASSERT_TRUE(store_->SetArchiveShipping(true).ok());
  auto id = store_->CreateSession(MakeNewSession(), MakeSteps(2));
  ASSERT_TRUE(id.ok());
  ASSERT_TRUE(store_->SetSessionState(*id, SessionState::kRunning, "go").ok());
  auto batch = store_->NextShipBatch(1000, 1000);
  ASSERT_TRUE(batch.ok()) << batch.status().ToString();
  ASSERT_EQ(batch->events.size(), 2u);
  EXPECT_EQ(batch->events[1].state, SessionState::kRunning);
  EXPECT_EQ(batch->events_through, batch->events[1].id);
  EXPECT_EQ(batch->uuids.at(*id), store_->GetSession(*id)->uuid);
  ASSERT_TRUE(store_->MarkShipped(*batch).ok());

  ASSERT_TRUE(store_->SetSessionState(*id, SessionState::kAborted, "stop").ok());
  auto next = store_->NextShipBatch(1000, 1000);
  ASSERT_TRUE(next.ok());
  ASSERT_EQ(next->events.size(), 1u);
  EXPECT_EQ(next->events[0].state, SessionState::kAborted);
  EXPECT_EQ(next->events[0].reason, "stop");
  ASSERT_TRUE(store_->MarkShipped(*next).ok());
  auto empty = store_->NextShipBatch(1000, 1000);
  ASSERT_TRUE(empty.ok());
  EXPECT_TRUE(empty->events.empty());
}

}  // namespace
}  // namespace brdf::storage
