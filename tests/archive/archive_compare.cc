#include "tests/archive/archive_compare.h"

#include <gtest/gtest.h>

#include "storage/archive/pg.h"
#include "storage/round_picks.h"
#include "storage/spectrum_blob.h"
#include "storage/uncertainty_columns.h"

namespace brdf::storage::testing {

// The archive's reading_uncertainty rows of a session are the readings' budgets, byte for byte:
// a row for each reading that has one, none for the others (not estimated).
void ExpectSameUncertainties(PgConnection& conn, const std::string& uuid,
                             const std::vector<ReadingRecord>& mine) {
  Result<PgResult> rows = conn.Query(
      "SELECT r.rig_reading_id, u.quantity, u.combined, u.independent, u.components, "
      "u.contributions, u.not_estimated, u.value FROM reading_uncertainty u JOIN readings r "
      "USING (session_uuid, step_index) WHERE session_uuid = $1 ORDER BY r.rig_reading_id",
      PgParams().Add(uuid));
  ASSERT_TRUE(rows.ok()) << rows.status().ToString();
  int row = 0;
  for (const ReadingRecord& r : mine) {
    if (!r.uncertainty.has_value()) continue;
    ASSERT_LT(row, rows->rows()) << "reading " << r.id << "'s uncertainty is not archived";
    Result<UncertaintyColumns> want = EncodeUncertainty(*r.uncertainty, r.grid.count);
    ASSERT_TRUE(want.ok()) << want.status().ToString();
    EXPECT_EQ(rows->Int64(row, 0), r.id);
    EXPECT_EQ(rows->Text(row, 1), want->quantity);
    EXPECT_EQ(rows->Bytes(row, 2), want->combined) << "reading " << r.id;
    EXPECT_EQ(rows->Bytes(row, 3), want->independent) << "reading " << r.id;
    EXPECT_EQ(rows->Text(row, 4), want->components);
    EXPECT_EQ(rows->Bytes(row, 5), want->contributions) << "reading " << r.id;
    EXPECT_EQ(rows->Text(row, 6), want->not_estimated);
    EXPECT_EQ(rows->Bytes(row, 7), want->value) << "reading " << r.id;
    ++row;
  }
  EXPECT_EQ(rows->rows(), row) << "the archive holds uncertainties of readings that have none";
}

// The archive's adaptive_rounds rows of a session are the rig's rounds, field for field (the picks
// as the rig encodes them), once each.
void ExpectSameRounds(PgConnection& conn, const std::string& uuid,
                      const std::vector<RoundRecord>& mine) {
  Result<PgResult> rows = conn.Query(
      "SELECT round, first_step, step_count, picks, predicted_gain, uncertainty_left, "
      "readings_used, created_at FROM adaptive_rounds WHERE session_uuid = $1 ORDER BY round",
      PgParams().Add(uuid));
  ASSERT_TRUE(rows.ok()) << rows.status().ToString();
  ASSERT_EQ(rows->rows(), static_cast<int>(mine.size())) << "rounds of session " << uuid;
  for (int i = 0; i < rows->rows(); ++i) {
    const RoundRecord& r = mine[static_cast<std::size_t>(i)];
    EXPECT_EQ(rows->Int64(i, 0), r.round);
    EXPECT_EQ(rows->Int64(i, 1), r.first_step) << "round " << r.round;
    EXPECT_EQ(rows->Int64(i, 2), r.step_count) << "round " << r.round;
    EXPECT_EQ(rows->Text(i, 3), EncodePicks(r.picks)) << "round " << r.round;
    EXPECT_EQ(rows->Double(i, 4), r.predicted_gain) << "round " << r.round;
    EXPECT_EQ(rows->Double(i, 5), r.uncertainty_left) << "round " << r.round;
    EXPECT_EQ(rows->Int64(i, 6), r.readings_used) << "round " << r.round;
    EXPECT_EQ(rows->Double(i, 7), r.created_at) << "round " << r.round;
  }
}

// Every reading and every event of every session of `store` is in the archive exactly once with
// the same content, and the archive holds no other reading or event of those sessions.
void ExpectArchiveHoldsExactly(const std::string& conninfo, SessionStore& store,
                               const std::string& rig) {
  Result<std::unique_ptr<PgConnection>> conn = PgConnection::Open(conninfo);
  ASSERT_TRUE(conn.ok()) << conn.status().ToString();
  Result<std::vector<SessionRecord>> sessions = store.ListSessions();
  ASSERT_TRUE(sessions.ok());
  std::int64_t total = 0;
  std::int64_t total_events = 0;
  for (const SessionRecord& s : *sessions) {
    SCOPED_TRACE("session " + std::to_string(s.id) + " " + s.uuid);
    Result<PgResult> row = (*conn)->Query(
        "SELECT rig, rig_session_id, state, done_steps, total_steps, plan_json, created_at "
        "FROM sessions WHERE uuid = $1",
        PgParams().Add(s.uuid));
    ASSERT_TRUE(row.ok()) << row.status().ToString();
    ASSERT_EQ(row->rows(), 1);
    EXPECT_EQ(row->Text(0, 0), rig);
    EXPECT_EQ(row->Int64(0, 1), s.id);
    EXPECT_EQ(row->Text(0, 2), ToString(s.state));
    EXPECT_EQ(row->Int64(0, 3), s.done_steps);
    EXPECT_EQ(row->Int64(0, 4), s.total_steps);
    EXPECT_EQ(row->Text(0, 5), s.plan_json);
    EXPECT_EQ(row->Double(0, 6), s.created_at);
    Result<PgResult> steps = (*conn)->Query(
        "SELECT count(*), count(*) FILTER (WHERE state = 'done') FROM steps "
        "WHERE session_uuid = $1",
        PgParams().Add(s.uuid));
    ASSERT_TRUE(steps.ok());
    EXPECT_EQ(steps->Int64(0, 0), s.total_steps);
    EXPECT_EQ(steps->Int64(0, 1), s.done_steps);

    Result<std::vector<ReadingRecord>> mine = store.GetReadings(s.id, 0, 1 << 20);
    ASSERT_TRUE(mine.ok());
    Result<PgResult> theirs = (*conn)->Query(
        "SELECT rig_reading_id, step_index, kind, spectrum, recorded_at, reference_reading_id, "
        "theta_i, flagged, quality_code FROM readings WHERE session_uuid = $1 "
        "ORDER BY rig_reading_id",
        PgParams().Add(s.uuid));
    ASSERT_TRUE(theirs.ok()) << theirs.status().ToString();
    ASSERT_EQ(theirs->rows(), static_cast<int>(mine->size()));
    for (int i = 0; i < theirs->rows(); ++i) {
      const ReadingRecord& r = (*mine)[static_cast<std::size_t>(i)];
      EXPECT_EQ(theirs->Int64(i, 0), r.id);
      EXPECT_EQ(theirs->Int64(i, 1), r.step_index);
      EXPECT_EQ(theirs->Text(i, 2), ToString(r.kind));
      EXPECT_EQ(theirs->Bytes(i, 3), EncodeSpectrum(r.spectrum)) << "reading " << r.id;
      EXPECT_EQ(theirs->Double(i, 4), r.recorded_at);
      EXPECT_EQ(theirs->OptionalInt64(i, 5), r.reference_reading_id);
      EXPECT_EQ(theirs->Double(i, 6), r.directions.theta_i);
      EXPECT_EQ(theirs->Text(i, 7), r.flagged ? "t" : "f");
      EXPECT_EQ(theirs->Int64(i, 8), r.quality_code);
    }
    total += theirs->rows();
    ExpectSameUncertainties(**conn, s.uuid, *mine);

    // The session's history of states, event by event.
    Result<std::vector<SessionEventRecord>> events = store.ListSessionEvents(s.id);
    ASSERT_TRUE(events.ok()) << events.status().ToString();
    EXPECT_FALSE(events->empty());
    Result<PgResult> archived = (*conn)->Query(
        "SELECT rig_event_id, at, state, reason FROM session_events WHERE session_uuid = $1 "
        "ORDER BY rig_event_id",
        PgParams().Add(s.uuid));
    ASSERT_TRUE(archived.ok()) << archived.status().ToString();
    ASSERT_EQ(archived->rows(), static_cast<int>(events->size()));
    for (int i = 0; i < archived->rows(); ++i) {
      const SessionEventRecord& e = (*events)[static_cast<std::size_t>(i)];
      EXPECT_EQ(archived->Int64(i, 0), e.id);
      EXPECT_EQ(archived->Double(i, 1), e.at);
      EXPECT_EQ(archived->Text(i, 2), ToString(e.state));
      EXPECT_EQ(archived->Text(i, 3), e.reason);
    }
    total_events += archived->rows();

    Result<std::vector<RoundRecord>> rounds = store.GetRounds(s.id);
    ASSERT_TRUE(rounds.ok()) << rounds.status().ToString();
    ExpectSameRounds(**conn, s.uuid, *rounds);
  }
  Result<PgResult> all = (*conn)->Query(
      "SELECT count(*) FROM readings r JOIN sessions s ON s.uuid = r.session_uuid WHERE s.rig = "
      "$1",
      PgParams().Add(rig));
  ASSERT_TRUE(all.ok());
  EXPECT_EQ(all->Int64(0, 0), total);
  Result<PgResult> all_events = (*conn)->Query(
      "SELECT count(*) FROM session_events e JOIN sessions s ON s.uuid = e.session_uuid "
      "WHERE s.rig = $1",
      PgParams().Add(rig));
  ASSERT_TRUE(all_events.ok()) << all_events.status().ToString();
  EXPECT_EQ(all_events->Int64(0, 0), total_events);
}

}  // namespace brdf::storage::testing
