// The shipper in process, on real parts: a real SQLite file (SessionStore), a real PostgreSQL
// (tests/support/pg/server.h) that is stopped, killed and restarted while sessions record, and
// the daemon's ArchiveShipper thread. After every fault the archive is compared with the rig's
// database reading by reading (ids, steps, every spectrum byte, timestamps): each reading is in
// the archive exactly once, and recording never waited for the archive.
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <atomic>
#include <chrono>
#include <cstring>
#include <functional>
#include <thread>

#include "core/plan/plan_json.h"
#include "daemon/engine/adaptive_rounds.h"
#include "daemon/engine/shipper.h"
#include "daemon/wire/round.h"
#include "storage/archive/pg.h"
#include "storage/archive/reader.h"
#include "storage/archive/schema.h"
#include "storage/archive/writer.h"
#include "storage/spectrum_blob.h"
#include "tests/archive/archive_compare.h"
#include "tests/storage/storage_test_util.h"
#include "tests/support/pg/server_fixture.h"

namespace brdf::storage {
namespace {

using namespace std::chrono_literals;
using brdf::testing::PgServer;
using brdf::testing::PgServerTest;
using daemon::ArchiveShipper;
using ::testing::HasSubstr;
using testing::MakeNewSession;
using testing::MakeReading;
using testing::MakeSteps;
using ::testing::Not;
using testing::TempDir;

// Records step `i` of a session made with MakeSteps: a move is completed, a measuring step gets
// its reading (samples name the latest reference).
Status RecordStep(SessionStore& store, std::int64_t session, int i,
                  std::optional<std::int64_t>& reference) {
  const StepKind kind = testing::KindOfStep(i);
  if (kind == StepKind::kMove) return store.CompleteStep(session, i);
  ReadingRecord r = MakeReading(i, *ReadingKindFor(kind));
  if (kind == StepKind::kSample) r.reference_reading_id = reference;
  if (kind == StepKind::kSample && i % 2 == 0) r.uncertainty = testing::MakeBudget(i, r.grid, 1);
  BRDF_ASSIGN_OR_RETURN(std::int64_t id, store.CompleteStepWithReading(session, i, r));
  if (kind == StepKind::kReference) reference = id;
  return Status::Ok();
}

// An adaptive plan (the rounds' spend is computed from its measurement settings).
const std::string kAdaptivePlan = R"({"name": "adaptive", "adaptive": {
  "target": {"expandedUncertainty": 0.001}, "budget": {"maxReadings": 40},
  "region": {"thetaIMaxDeg": 80, "thetaOMaxDeg": 80}, "method": "ADAPTIVE_JUDGE_OCTANT",
  "delta": {"start": 0, "stop": 22.5, "step": 11.25},
  "seed": {"retroReadings": 3, "readingsPerDelta": 4}, "roundReadings": 6},
  "measurement": {"integrationMs": 100, "averages": 1}})";

// Steps first … first + n − 1 of the standard test plan (moves, references, samples).
std::vector<StepRecord> StepsFrom(int first, int n) {
  std::vector<StepRecord> steps = MakeSteps(first + n);
  return std::vector<StepRecord>(steps.begin() + first, steps.end());
}

RoundRecord MakeRound(std::int64_t session, int number, int first_step) {
  RoundRecord r;
  r.session_id = session;
  r.round = number;
  r.first_step = first_step;
  r.picks = {{Pose{12.5, -35, 0, 11.25}, 0.0123456789012345},
             {Pose{1.0 / 3, 170.0 - number, 0, 22.5}, 1e-7 * number}};
  r.predicted_gain = 0.0123457789012345;
  r.uncertainty_left = 0.0712 / number;
  r.readings_used = 10 + 6 * number;
  return r;
}

// An adaptive session of a 12-step seed and two rounds (steps 12-17 and 18-22), running; the
// rounds' steps recorded up to `recorded` (exclusive). `after_seed` runs once the seed is
// recorded, before the first round is stored.
Result<std::int64_t> RecordAdaptiveSession(
    SessionStore& store, int recorded, const std::function<void()>& after_seed = [] {}) {
  NewSession n = MakeNewSession("adaptive paint");
  n.rig = "rig-a";
  n.plan_kind = "adaptive";
  n.plan_json = kAdaptivePlan;
  BRDF_ASSIGN_OR_RETURN(std::int64_t id, store.CreateSession(n, MakeSteps(12)));
  BRDF_RETURN_IF_ERROR(store.SetSessionState(id, SessionState::kRunning, ""));
  std::optional<std::int64_t> ref;
  for (int i = 0; i < 12; ++i) BRDF_RETURN_IF_ERROR(RecordStep(store, id, i, ref));
  after_seed();
  BRDF_RETURN_IF_ERROR(store.AppendRound(MakeRound(id, 1, 12), StepsFrom(12, 6)));
  for (int i = 12; i < std::min(recorded, 18); ++i) {
    BRDF_RETURN_IF_ERROR(RecordStep(store, id, i, ref));
  }
  BRDF_RETURN_IF_ERROR(store.AppendRound(MakeRound(id, 2, 18), StepsFrom(18, 5)));
  for (int i = 18; i < recorded; ++i) BRDF_RETURN_IF_ERROR(RecordStep(store, id, i, ref));
  return id;
}

class ArchiveShipperTest : public PgServerTest {
 protected:
  void SetUp() override {
    PgServerTest::SetUp();
    if (!PgReady()) return;
    credentials_ = *PgServer::WriteCredentials(dir_.File("archive.conninfo"), pg_->conninfo());
  }
  void TearDown() override {
    if (HasFailure() && pg_ != nullptr) std::cerr << "---- postgres log ----\n" << pg_->log();
  }

  std::shared_ptr<SessionStore> OpenStore(const std::string& name) {
    Result<std::unique_ptr<SessionStore>> s = SessionStore::Open(dir_.File(name));
    EXPECT_TRUE(s.ok()) << s.status().ToString();
    return s.ok() ? std::shared_ptr<SessionStore>(std::move(*s)) : nullptr;
  }
  std::unique_ptr<ArchiveShipper> StartShipper(std::shared_ptr<SessionStore> store,
                                               const std::string& rig) {
    ArchiveShipper::Options o;
    o.credentials_path = credentials_;
    o.rig = rig;
    o.batch_readings = 50;
    o.retry = 100ms;
    o.poll = 20ms;
    Result<std::unique_ptr<ArchiveShipper>> s = ArchiveShipper::Start(std::move(store), o);
    EXPECT_TRUE(s.ok()) << s.status().ToString();
    return s.ok() ? std::move(*s) : nullptr;
  }
  // Until the shipper says it is caught up with nothing left (or 30 s).
  bool WaitCaughtUp(ArchiveShipper& shipper) {
    const auto deadline = std::chrono::steady_clock::now() + 30s;
    while (std::chrono::steady_clock::now() < deadline) {
      const v1::ArchiveStatus s = shipper.Snapshot();
      if (s.state() == v1::ARCHIVE_STATE_CAUGHT_UP && s.lag_readings() == 0) return true;
      std::this_thread::sleep_for(20ms);
    }
    return false;
  }
  v1::ArchiveState WaitState(ArchiveShipper& shipper, v1::ArchiveState want) {
    const auto deadline = std::chrono::steady_clock::now() + 20s;
    v1::ArchiveState seen = v1::ARCHIVE_STATE_UNSPECIFIED;
    while (std::chrono::steady_clock::now() < deadline) {
      seen = shipper.Snapshot().state();
      if (seen == want) return seen;
      std::this_thread::sleep_for(20ms);
    }
    return seen;
  }

  void ExpectArchiveHoldsExactly(SessionStore& store, const std::string& rig) {
    testing::ExpectArchiveHoldsExactly(pg_->conninfo(), store, rig);
  }

  TempDir dir_;
  std::string credentials_;
};

TEST_F(ArchiveShipperTest, ShipsEverythingRecordedWithTheCatalogue) {
  auto store = OpenStore("rig-a.db");
  NewSession n = MakeNewSession();
  n.rig = "rig-a";
  n.plan_json = R"({"name": "gloss", "sample": {"id": "P-7", "name": "Red Gloss",
    "material": "paint", "tags": ["glossy", "red \"wine\""], "whiteStandardId": "RS-3"}})";
  Result<std::int64_t> id = store->CreateSession(n, MakeSteps(40));
  ASSERT_TRUE(id.ok());
  ASSERT_TRUE(store->SetSessionState(*id, SessionState::kRunning, "").ok());
  ASSERT_TRUE(store->RecordDevice({0, *id, "spectroradiometer", "PR-650", "60954201", 0}).ok());
  ASSERT_TRUE(store->AppendAudit({0, 0, "operator", "lab-pc", "session.start", *id, "x"}).ok());
  auto shipper = StartShipper(store, "rig-a");
  std::optional<std::int64_t> ref;
  for (int i = 0; i < 40; ++i) ASSERT_TRUE(RecordStep(*store, *id, i, ref).ok());
  ASSERT_TRUE(store->SetSessionState(*id, SessionState::kCompleted, "").ok());
  ASSERT_TRUE(WaitCaughtUp(*shipper)) << shipper->Snapshot().DebugString();
  ExpectArchiveHoldsExactly(*store, "rig-a");
  EXPECT_EQ(*pg_->Psql("SELECT sample_id || '|' || sample_name || '|' || material || '|' || "
                       "array_to_string(tags, ';') || '|' || white_standard_id FROM sessions"),
            "P-7|Red Gloss|paint|glossy;red \"wine\"|RS-3");
  EXPECT_EQ(*pg_->Psql("SELECT count(*) FROM sessions WHERE 'glossy' = ANY (tags)"), "1");
  EXPECT_EQ(*pg_->Psql("SELECT kind || '/' || serial FROM devices"), "spectroradiometer/60954201");
  EXPECT_EQ(*pg_->Psql("SELECT action || '/' || actor FROM audit"), "session.start/lab-pc");
  EXPECT_EQ(shipper->Snapshot().shipped_readings(), 36u);  // 40 steps less 4 moves
  EXPECT_EQ(*pg_->Psql("SELECT string_agg(state, ',' ORDER BY rig_event_id) FROM session_events"),
            "queued,running,completed");
  // brdf-archive's reader answers a session's events as the rig's store does.
  auto reader = ArchiveReader::Open(pg_->conninfo());
  ASSERT_TRUE(reader.ok()) << reader.status().ToString();
  const std::int64_t archive_id = std::stoll(*pg_->Psql("SELECT archive_id FROM sessions"));
  auto archived = (*reader)->ListSessionEvents(archive_id);
  ASSERT_TRUE(archived.ok()) << archived.status().ToString();
  auto devices = (*reader)->GetSessionDevices(archive_id);  // the BiRD export's meter model
  ASSERT_TRUE(devices.ok()) << devices.status().ToString();
  ASSERT_EQ(devices->size(), 1u);
  EXPECT_EQ((*devices)[0].model, "PR-650");
  EXPECT_EQ((*devices)[0].serial, "60954201");
  EXPECT_EQ((*devices)[0].session_id, archive_id);
  auto recorded = store->ListSessionEvents(*id);
  ASSERT_TRUE(recorded.ok());
  ASSERT_EQ(archived->size(), recorded->size());
  for (std::size_t i = 0; i < archived->size(); ++i) {
    EXPECT_EQ((*archived)[i].id, (*recorded)[i].id);
    EXPECT_EQ((*archived)[i].session_id, archive_id);
    EXPECT_EQ((*archived)[i].at, (*recorded)[i].at);
    EXPECT_EQ((*archived)[i].state, (*recorded)[i].state);
    EXPECT_EQ((*archived)[i].reason, (*recorded)[i].reason);
  }
  EXPECT_EQ((*reader)->ListSessionEvents(archive_id + 1000).status().code(), StatusCode::kNotFound);
  // …and its readings with their uncertainty budgets, or none (not estimated), as the rig's.
  auto archived_readings = (*reader)->GetReadings(archive_id, 0, 1000);
  ASSERT_TRUE(archived_readings.ok()) << archived_readings.status().ToString();
  auto recorded_readings = store->GetReadings(*id, 0, 1000);
  ASSERT_TRUE(recorded_readings.ok());
  ASSERT_EQ(archived_readings->size(), recorded_readings->size());
  int with_budget = 0;
  for (std::size_t i = 0; i < archived_readings->size(); ++i) {
    const auto& theirs = (*archived_readings)[i].uncertainty;
    const auto& mine = (*recorded_readings)[i].uncertainty;
    ASSERT_EQ(theirs.has_value(), mine.has_value()) << "reading " << (*recorded_readings)[i].id;
    if (!mine.has_value()) continue;
    ++with_budget;
    EXPECT_EQ(theirs->quantity, mine->quantity);
    EXPECT_EQ(theirs->value, mine->value);
    EXPECT_EQ(theirs->combined, mine->combined);
    EXPECT_EQ(theirs->independent, mine->independent);
    EXPECT_EQ(theirs->not_estimated, mine->not_estimated);
    ASSERT_EQ(theirs->components.size(), mine->components.size());
    for (std::size_t c = 0; c < mine->components.size(); ++c) {
      EXPECT_EQ(theirs->components[c].name, mine->components[c].name);
      EXPECT_EQ(theirs->components[c].shared, mine->components[c].shared);
      EXPECT_EQ(theirs->components[c].contribution, mine->components[c].contribution);
    }
  }
  EXPECT_EQ(with_budget, 16);  // the samples of even steps: 2, 4, 6, 8 of each ten
}

// The archive commits a batch and the rig dies before it records its marks: the batch is sent
// again and changes nothing.
TEST_F(ArchiveShipperTest, ABatchShippedTwiceChangesNothing) {
  auto store = OpenStore("rig-a.db");
  ASSERT_TRUE(store->SetArchiveShipping(true).ok());
  NewSession n = MakeNewSession();
  n.rig = "rig-a";
  Result<std::int64_t> id = store->CreateSession(n, MakeSteps(30));
  ASSERT_TRUE(store->SetSessionState(*id, SessionState::kRunning, "").ok());
  std::optional<std::int64_t> ref;
  for (int i = 0; i < 30; ++i) ASSERT_TRUE(RecordStep(*store, *id, i, ref).ok());
  Result<std::unique_ptr<PgConnection>> conn = PgConnection::Open(pg_->conninfo());
  ASSERT_TRUE(conn.ok());
  ASSERT_TRUE(MigrateArchive(**conn).ok());
  Result<ShipBatch> batch = store->NextShipBatch(1000, 1000);
  ASSERT_TRUE(batch.ok()) << batch.status().ToString();
  ASSERT_EQ(batch->readings.size(), 27u);
  ASSERT_TRUE(WriteToArchive(**conn, "rig-a", *batch).ok());
  // ... crash here: no MarkShipped. The next run ships the same rows again.
  Result<ShipBatch> again = store->NextShipBatch(1000, 1000);
  ASSERT_TRUE(again.ok());
  EXPECT_EQ(again->readings.size(), 27u);
  Status st = WriteToArchive(**conn, "rig-a", *again);
  ASSERT_TRUE(st.ok()) << st.ToString();
  ASSERT_TRUE(store->MarkShipped(*again).ok());
  EXPECT_EQ(*pg_->Psql("SELECT count(*) FROM readings"), "27");
  EXPECT_EQ(*pg_->Psql("SELECT count(*) FROM steps"), "30");
  EXPECT_EQ(*pg_->Psql("SELECT count(*) FROM session_events"), "2");  // queued, running
  Result<ShipBatch> after = store->NextShipBatch(1000, 1000);
  ASSERT_TRUE(after.ok());
  EXPECT_TRUE(after->empty());
  ExpectArchiveHoldsExactly(*store, "rig-a");
}

// Two rigs record at the same time; the archive is stopped in the middle of their sessions, then
// killed, and comes back: recording never waits, and in the end the archive holds exactly both
// rigs' readings.
TEST_F(ArchiveShipperTest, TwoRigsThroughAnArchiveStoppedAndKilledEndExact) {
  auto a = OpenStore("rig-a.db");
  auto b = OpenStore("rig-b.db");
  auto ship_a = StartShipper(a, "rig-a");
  auto ship_b = StartShipper(b, "rig-b");
  constexpr int kSteps = 300;
  std::atomic<int> phase{0};
  std::atomic<double> slowest_ms{0};
  auto record = [&](std::shared_ptr<SessionStore> store, const std::string& rig) {
    for (int session = 0; session < 2; ++session) {
      NewSession n = MakeNewSession(rig + " session " + std::to_string(session));
      n.rig = rig;
      Result<std::int64_t> id = store->CreateSession(n, MakeSteps(kSteps));
      ASSERT_TRUE(id.ok());
      ASSERT_TRUE(store->SetSessionState(*id, SessionState::kRunning, "").ok());
      std::optional<std::int64_t> ref;
      for (int i = 0; i < kSteps; ++i) {
        const auto t0 = std::chrono::steady_clock::now();
        ASSERT_TRUE(RecordStep(*store, *id, i, ref).ok());
        const double ms =
            std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0)
                .count();
        if (ms > slowest_ms) slowest_ms = ms;
        std::this_thread::sleep_for(2ms);
      }
      ASSERT_TRUE(store->SetSessionState(*id, SessionState::kCompleted, "").ok());
    }
    ++phase;
  };
  std::thread ta(record, a, "rig-a");
  std::thread tb(record, b, "rig-b");
  std::this_thread::sleep_for(300ms);
  ASSERT_TRUE(pg_->Stop().ok());
  EXPECT_EQ(WaitState(*ship_a, v1::ARCHIVE_STATE_UNREACHABLE), v1::ARCHIVE_STATE_UNREACHABLE);
  std::this_thread::sleep_for(300ms);
  const v1::ArchiveStatus away = ship_b->Snapshot();
  EXPECT_GT(away.lag_readings(), 0u);
  EXPECT_GT(away.lag_seconds(), 0.0);
  ASSERT_TRUE(pg_->Restart().ok());
  std::this_thread::sleep_for(400ms);
  ASSERT_TRUE(pg_->Kill().ok());  // as a crash, mid-batch
  std::this_thread::sleep_for(300ms);
  ASSERT_TRUE(pg_->Restart().ok());
  ta.join();
  tb.join();
  ASSERT_EQ(phase.load(), 2);
  ASSERT_TRUE(WaitCaughtUp(*ship_a)) << ship_a->Snapshot().DebugString();
  ASSERT_TRUE(WaitCaughtUp(*ship_b)) << ship_b->Snapshot().DebugString();
  ExpectArchiveHoldsExactly(*a, "rig-a");
  ExpectArchiveHoldsExactly(*b, "rig-b");
  const std::int64_t per_rig = 2 * (kSteps - kSteps / 10);
  EXPECT_EQ(*pg_->Psql("SELECT count(*) FROM readings"), std::to_string(2 * per_rig));
  EXPECT_EQ(*pg_->Psql("SELECT count(DISTINCT rig) FROM sessions"), "2");
  // Recording never waited for the archive (a commit with fsync is milliseconds; 500 is far).
  EXPECT_LT(slowest_ms.load(), 500.0);
}

// The archive cuts the shipper's connection again and again (pg_terminate_backend, as a flaky
// network or an administrator would) while a session records: the archive still ends exact.
TEST_F(ArchiveShipperTest, DroppedConnectionsMidShippingEndExact) {
  auto store = OpenStore("rig-a.db");
  auto shipper = StartShipper(store, "rig-a");
  NewSession n = MakeNewSession();
  n.rig = "rig-a";
  Result<std::int64_t> id = store->CreateSession(n, MakeSteps(400));
  ASSERT_TRUE(store->SetSessionState(*id, SessionState::kRunning, "").ok());
  std::atomic<bool> done{false};
  int cuts = 0;
  std::thread cutter([&] {
    while (!done) {
      Result<std::string> killed = pg_->Psql(
          "SELECT count(pg_terminate_backend(pid)) FROM pg_stat_activity "
          "WHERE application_name = 'brdfd'");
      if (killed.ok() && *killed != "0") ++cuts;
      std::this_thread::sleep_for(30ms);
    }
  });
  std::optional<std::int64_t> ref;
  for (int i = 0; i < 400; ++i) {
    ASSERT_TRUE(RecordStep(*store, *id, i, ref).ok());
    std::this_thread::sleep_for(1ms);
  }
  done = true;
  cutter.join();
  EXPECT_GT(cuts, 3) << "the connection was hardly cut";
  ASSERT_TRUE(WaitCaughtUp(*shipper)) << shipper->Snapshot().DebugString();
  ExpectArchiveHoldsExactly(*store, "rig-a");
}

// A wrong password: the shipper says REFUSED (without the password), recording goes on; once the
// credentials file is fixed it catches up without a restart.
TEST_F(ArchiveShipperTest, WrongPasswordNeverPausesRecordingAndFixingTheFileCatchesUp) {
  ASSERT_TRUE(
      PgServer::WriteCredentials(credentials_, pg_->conninfo_with_password("wrong-secret-123456"))
          .ok());
  auto store = OpenStore("rig-a.db");
  auto shipper = StartShipper(store, "rig-a");
  NewSession n = MakeNewSession();
  n.rig = "rig-a";
  Result<std::int64_t> id = store->CreateSession(n, MakeSteps(50));
  ASSERT_TRUE(store->SetSessionState(*id, SessionState::kRunning, "").ok());
  std::optional<std::int64_t> ref;
  for (int i = 0; i < 50; ++i) ASSERT_TRUE(RecordStep(*store, *id, i, ref).ok());
  ASSERT_EQ(WaitState(*shipper, v1::ARCHIVE_STATE_REFUSED), v1::ARCHIVE_STATE_REFUSED);
  const v1::ArchiveStatus refused = shipper->Snapshot();
  EXPECT_THAT(refused.detail(), HasSubstr("password"));
  EXPECT_THAT(refused.detail(), Not(HasSubstr("wrong-secret-123456")));
  EXPECT_EQ(refused.lag_readings(), 45u);
  ASSERT_TRUE(PgServer::WriteCredentials(credentials_, pg_->conninfo()).ok());
  ASSERT_TRUE(WaitCaughtUp(*shipper)) << shipper->Snapshot().DebugString();
  ExpectArchiveHoldsExactly(*store, "rig-a");
}

// An unreachable archive (nothing listens) and a missing credentials file: recording goes on.
TEST_F(ArchiveShipperTest, UnreachableArchiveAndMissingCredentialsNeverPauseRecording) {
  ASSERT_TRUE(pg_->Stop().ok());
  auto store = OpenStore("rig-a.db");
  auto shipper = StartShipper(store, "rig-a");
  NewSession n = MakeNewSession();
  Result<std::int64_t> id = store->CreateSession(n, MakeSteps(20));
  ASSERT_TRUE(store->SetSessionState(*id, SessionState::kRunning, "").ok());
  std::optional<std::int64_t> ref;
  for (int i = 0; i < 20; ++i) ASSERT_TRUE(RecordStep(*store, *id, i, ref).ok());
  EXPECT_EQ(WaitState(*shipper, v1::ARCHIVE_STATE_UNREACHABLE), v1::ARCHIVE_STATE_UNREACHABLE);
  EXPECT_EQ(shipper->Snapshot().lag_readings(), 18u);
  shipper.reset();
  ArchiveShipper::Options o;
  o.credentials_path = dir_.File("no-such.conninfo");
  o.rig = "rig-a";
  o.retry = 100ms;
  auto missing = ArchiveShipper::Start(store, o);
  ASSERT_TRUE(missing.ok());
  EXPECT_EQ(WaitState(**missing, v1::ARCHIVE_STATE_REFUSED), v1::ARCHIVE_STATE_REFUSED);
  EXPECT_THAT((*missing)->Snapshot().detail(), HasSubstr("no-such.conninfo"));
}

// Sessions recorded before shipping was on (or while it was off) are shipped once it is on.
TEST_F(ArchiveShipperTest, SessionsFromBeforeShippingAreShippedWhenItIsTurnedOn) {
  auto store = OpenStore("rig-a.db");
  ASSERT_TRUE(store->SetArchiveShipping(false).ok());
  NewSession n = MakeNewSession();
  n.rig = "rig-a";
  Result<std::int64_t> id = store->CreateSession(n, MakeSteps(20));
  ASSERT_TRUE(store->SetSessionState(*id, SessionState::kRunning, "").ok());
  std::optional<std::int64_t> ref;
  for (int i = 0; i < 20; ++i) ASSERT_TRUE(RecordStep(*store, *id, i, ref).ok());
  EXPECT_EQ(store->ShippingLag()->pending_changes, 0);  // the outbox stays empty while off
  auto shipper = StartShipper(store, "rig-a");
  ASSERT_TRUE(WaitCaughtUp(*shipper));
  ExpectArchiveHoldsExactly(*store, "rig-a");
}

// An adaptive session's rounds reach the archive with its steps (total_steps grown by each round),
// and brdf-archive's reader gives them back as the rig's ListAdaptiveRounds answers them: the
// same messages, spend included.
TEST_F(ArchiveShipperTest, AdaptiveRoundsReachTheArchiveAsTheRigAnswersThem) {
  auto store = OpenStore("rig-a.db");
  auto shipper = StartShipper(store, "rig-a");
  // The seed is in the archive before the rounds are stored: the session's row grows with them.
  Result<std::int64_t> id = RecordAdaptiveSession(*store, 23, [&] {
    EXPECT_TRUE(WaitCaughtUp(*shipper)) << shipper->Snapshot().DebugString();
    EXPECT_EQ(*pg_->Psql("SELECT total_steps FROM sessions"), "12");
  });
  ASSERT_TRUE(id.ok()) << id.status().ToString();
  ASSERT_TRUE(store->SetSessionState(*id, SessionState::kCompleted, "adaptive: done").ok());
  // A session of another kind has no rounds.
  NewSession plain = MakeNewSession();
  plain.rig = "rig-a";
  Result<std::int64_t> other = store->CreateSession(plain, MakeSteps(5));
  ASSERT_TRUE(other.ok());
  ASSERT_TRUE(WaitCaughtUp(*shipper)) << shipper->Snapshot().DebugString();
  ExpectArchiveHoldsExactly(*store, "rig-a");
  EXPECT_EQ(*pg_->Psql("SELECT total_steps FROM sessions WHERE name = 'adaptive paint'"), "23");

  Result<v1::Plan> plan = plan::ParsePlanJson(kAdaptivePlan);
  ASSERT_TRUE(plan.ok()) << plan.status().ToString();
  Result<std::vector<v1::AdaptiveRound>> rig =
      daemon::StoredRounds(*store, *id, *plan, plan::RigDescription());
  ASSERT_TRUE(rig.ok()) << rig.status().ToString();
  ASSERT_EQ(rig->size(), 2u);
  auto reader = ArchiveReader::Open(pg_->conninfo());
  ASSERT_TRUE(reader.ok()) << reader.status().ToString();
  const std::int64_t archive_id =
      std::stoll(*pg_->Psql("SELECT archive_id FROM sessions WHERE name = 'adaptive paint'"));
  Result<std::vector<ArchivedRound>> archived = (*reader)->GetRounds(archive_id);
  ASSERT_TRUE(archived.ok()) << archived.status().ToString();
  ASSERT_EQ(archived->size(), rig->size());
  for (std::size_t i = 0; i < rig->size(); ++i) {
    EXPECT_EQ((*archived)[i].record.session_id, archive_id);
    const v1::AdaptiveRound answered = daemon::ToProtoRound((*archived)[i]);
    EXPECT_EQ(answered.SerializeAsString(), (*rig)[i].SerializeAsString())
        << "round " << i + 1 << "\narchive: " << answered.DebugString()
        << "\nrig: " << (*rig)[i].DebugString();
  }
  // The spend is the rig's timing, not zeros: the second round starts where the first ended.
  EXPECT_GT((*rig)[0].spent_rig_s(), 0);
  EXPECT_GT((*rig)[0].rig_s(), 0);
  EXPECT_DOUBLE_EQ((*rig)[1].spent_rig_s(), (*rig)[0].spent_rig_s() + (*rig)[0].rig_s());
  const std::int64_t plain_id =
      std::stoll(*pg_->Psql("SELECT archive_id FROM sessions WHERE name = 'paint sample'"));
  Result<std::vector<ArchivedRound>> none = (*reader)->GetRounds(plain_id);
  ASSERT_TRUE(none.ok()) << none.status().ToString();
  EXPECT_TRUE(none->empty());
  EXPECT_EQ((*reader)->GetRounds(archive_id + 1000).status().code(), StatusCode::kNotFound);
}

// The archive commits a batch holding rounds and the rig dies before recording its marks: the
// batch is sent again and each round is in the archive once. A round goes with its first step;
// a later change of another of its steps does not send it again.
TEST_F(ArchiveShipperTest, ARoundShippedTwiceIsArchivedOnce) {
  auto store = OpenStore("rig-a.db");
  ASSERT_TRUE(store->SetArchiveShipping(true).ok());
  Result<std::int64_t> id = RecordAdaptiveSession(*store, 18);
  ASSERT_TRUE(id.ok()) << id.status().ToString();
  Result<std::unique_ptr<PgConnection>> conn = PgConnection::Open(pg_->conninfo());
  ASSERT_TRUE(conn.ok());
  ASSERT_TRUE(MigrateArchive(**conn).ok());
  Result<ShipBatch> batch = store->NextShipBatch(1000, 1000);
  ASSERT_TRUE(batch.ok()) << batch.status().ToString();
  ASSERT_EQ(batch->rounds.size(), 2u);
  ASSERT_TRUE(WriteToArchive(**conn, "rig-a", *batch).ok());
  // ... kill -9 here: no MarkShipped. The next run sends the same rounds again.
  Result<ShipBatch> again = store->NextShipBatch(1000, 1000);
  ASSERT_TRUE(again.ok());
  EXPECT_EQ(again->rounds.size(), 2u);
  Status st = WriteToArchive(**conn, "rig-a", *again);
  ASSERT_TRUE(st.ok()) << st.ToString();
  ASSERT_TRUE(store->MarkShipped(*again).ok());
  EXPECT_EQ(*pg_->Psql("SELECT count(*) FROM adaptive_rounds"), "2");
  EXPECT_EQ(*pg_->Psql("SELECT string_agg(round || ':' || first_step || '+' || step_count, ',' "
                       "ORDER BY round) FROM adaptive_rounds"),
            "1:12+6,2:18+5");
  ExpectArchiveHoldsExactly(*store, "rig-a");

  std::optional<std::int64_t> ref;  // step 11's reference reading
  for (const ReadingRecord& r : *store->GetReadings(*id, 0, 1000)) {
    if (r.step_index == 11) ref = r.id;
  }
  ASSERT_TRUE(RecordStep(*store, *id, 19, ref).ok());  // not round 2's first step
  Result<ShipBatch> later = store->NextShipBatch(1000, 1000);
  ASSERT_TRUE(later.ok());
  EXPECT_EQ(later->steps.size(), 1u);
  EXPECT_TRUE(later->rounds.empty());
  ASSERT_TRUE(WriteToArchive(**conn, "rig-a", *later).ok());
  ASSERT_TRUE(store->MarkShipped(*later).ok());
  ASSERT_TRUE(RecordStep(*store, *id, 18, ref).ok());  // round 2's first step
  Result<ShipBatch> first = store->NextShipBatch(1000, 1000);
  ASSERT_TRUE(first.ok());
  ASSERT_EQ(first->rounds.size(), 1u);
  EXPECT_EQ(first->rounds[0].record.round, 2);
  ASSERT_TRUE(WriteToArchive(**conn, "rig-a", *first).ok());
  ASSERT_TRUE(store->MarkShipped(*first).ok());
  EXPECT_EQ(*pg_->Psql("SELECT count(*) FROM adaptive_rounds"), "2");
  ExpectArchiveHoldsExactly(*store, "rig-a");
}

// A rig whose rounds were stored before its brdfd shipped them (their steps in the archive, the
// rounds not): the first start of a shipper that does ships them, once.
TEST_F(ArchiveShipperTest, RoundsStoredBeforeTheyWereShippedReachTheArchiveOnce) {
  auto store = OpenStore("rig-a.db");
  ASSERT_TRUE(store->SetArchiveShipping(true).ok());
  Result<std::int64_t> id = RecordAdaptiveSession(*store, 23);
  ASSERT_TRUE(id.ok()) << id.status().ToString();
  {
    auto shipper = StartShipper(store, "rig-a");
    ASSERT_TRUE(WaitCaughtUp(*shipper)) << shipper->Snapshot().DebugString();
  }
  // As an older brdfd left them: no rounds in the archive, no 'rounds' mark on the rig.
  ASSERT_TRUE(pg_->Psql("DELETE FROM adaptive_rounds").ok());
  auto raw = Database::Open(dir_.File("rig-a.db"));
  ASSERT_TRUE(raw.ok()) << raw.status().ToString();
  ASSERT_TRUE((*raw)->Exec("DELETE FROM archive_marks WHERE name = 'rounds'").ok());
  raw->reset();
  auto shipper = StartShipper(store, "rig-a");
  ASSERT_TRUE(WaitCaughtUp(*shipper)) << shipper->Snapshot().DebugString();
  ExpectArchiveHoldsExactly(*store, "rig-a");
  EXPECT_EQ(*pg_->Psql("SELECT count(*) FROM adaptive_rounds"), "2");
  // Once: turning shipping on again queues nothing.
  shipper.reset();
  ASSERT_TRUE(store->SetArchiveShipping(true).ok());
  EXPECT_EQ(store->ShippingLag()->pending_changes, 0);
}

}  // namespace
}  // namespace brdf::storage
