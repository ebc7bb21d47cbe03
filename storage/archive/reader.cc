#include "storage/archive/reader.h"

#include <string_view>
#include <utility>

#include "storage/archive/schema.h"
#include "storage/round_picks.h"
#include "storage/spectrum_blob.h"
#include "storage/uncertainty_columns.h"

namespace brdf::storage {
namespace {

// Connections kept for reuse; more are opened while more queries run at once.
constexpr std::size_t kMaxIdleConnections = 8;

constexpr std::string_view kSessionColumns =
    "archive_id, name, plan_kind, plan_json, state, state_reason, created_at, started_at, "
    "finished_at, created_by_role, total_steps, done_steps, white_reflectance, meter_serial, "
    "config_json, uuid, rig, "
    // The session's grid: its first reading's (as the rig's store says it, session_rows.cc).
    "(SELECT wl_start_nm FROM readings WHERE readings.session_uuid = sessions.uuid "
    "ORDER BY rig_reading_id LIMIT 1), "
    "(SELECT wl_step_nm FROM readings WHERE readings.session_uuid = sessions.uuid "
    "ORDER BY rig_reading_id LIMIT 1), "
    "(SELECT wl_count FROM readings WHERE readings.session_uuid = sessions.uuid "
    "ORDER BY rig_reading_id LIMIT 1)";

constexpr std::string_view kStepsOfSession = R"sql(
SELECT step_index, kind, alpha, beta, gamma, delta, prompt, prompt_kind, expected_action,
  target_theta_i, target_phi_i, target_theta_o, target_phi_o, label, state, note, completed_at
FROM steps WHERE session_uuid = (SELECT uuid FROM sessions WHERE archive_id = $1)
ORDER BY step_index
)sql";

constexpr std::string_view kReadingsOfSession = R"sql(
SELECT rig_reading_id, step_index, kind, alpha, beta, gamma, delta, theta_i, phi_i, theta_o,
  phi_o, wl_start_nm, wl_step_nm, wl_count, spectrum, quality_code, flagged, integration_ms,
  attempts, note, reference_reading_id, dark_reading_id, meter_serial, recorded_at, quantity,
  value, combined, independent, components, contributions, not_estimated
FROM readings LEFT JOIN reading_uncertainty USING (session_uuid, step_index)
WHERE session_uuid = (SELECT uuid FROM sessions WHERE archive_id = $1)
  AND rig_reading_id > $2
ORDER BY rig_reading_id LIMIT $3
)sql";

constexpr std::string_view kReadingPointsOfSession = R"sql(
SELECT rig_reading_id, kind, alpha, beta, gamma, delta, theta_i, phi_i, theta_o, phi_o, flagged
FROM readings WHERE session_uuid = (SELECT uuid FROM sessions WHERE archive_id = $1)
  AND rig_reading_id > $2
ORDER BY rig_reading_id LIMIT $3
)sql";

constexpr std::string_view kEventsOfSession = R"sql(
SELECT rig_event_id, at, state, reason
FROM session_events WHERE session_uuid = (SELECT uuid FROM sessions WHERE archive_id = $1)
ORDER BY rig_event_id
)sql";

constexpr std::string_view kDevicesOfSession = R"sql(
SELECT rig_device_id, kind, model, serial, first_seen
FROM devices WHERE session_uuid = (SELECT uuid FROM sessions WHERE archive_id = $1)
ORDER BY rig_device_id
)sql";

constexpr std::string_view kRoundsOfSession = R"sql(
SELECT round, first_step, step_count, picks, predicted_gain, uncertainty_left, readings_used,
  created_at, spent_rig_s, spent_prompts, rig_s, prompts
FROM adaptive_rounds WHERE session_uuid = (SELECT uuid FROM sessions WHERE archive_id = $1)
ORDER BY round
)sql";

std::string SessionName(std::int64_t id) {
  return "session " + std::to_string(id);
}

Result<SessionRecord> SessionAt(const PgResult& r, int row) {
  SessionRecord s;
  s.id = r.Int64(row, 0);
  s.name = std::string(r.Text(row, 1));
  s.plan_kind = std::string(r.Text(row, 2));
  s.plan_json = std::string(r.Text(row, 3));
  Result<SessionState> state = ParseSessionState(std::string(r.Text(row, 4)));
  if (!state.ok()) return state.status().WithContext("archived " + SessionName(s.id));
  s.state = *state;
  s.state_reason = std::string(r.Text(row, 5));
  s.created_at = r.Double(row, 6);
  s.started_at = r.OptionalDouble(row, 7);
  s.finished_at = r.OptionalDouble(row, 8);
  s.created_by_role = std::string(r.Text(row, 9));
  s.total_steps = static_cast<int>(r.Int64(row, 10));
  s.done_steps = static_cast<int>(r.Int64(row, 11));
  s.white_reflectance = r.OptionalDouble(row, 12);
  s.meter_serial = std::string(r.Text(row, 13));
  s.config_json = std::string(r.Text(row, 14));
  s.uuid = std::string(r.Text(row, 15));
  s.rig = std::string(r.Text(row, 16));
  if (!r.IsNull(row, 19)) {
    s.grid = WavelengthGrid{r.Double(row, 17), r.Double(row, 18),
                            static_cast<std::size_t>(r.Int64(row, 19))};
  }
  return s;
}

Result<StepRecord> StepAt(const PgResult& r, int row, std::int64_t session) {
  StepRecord s;
  s.session_id = session;
  s.step_index = static_cast<int>(r.Int64(row, 0));
  BRDF_ASSIGN_OR_RETURN(StepKind kind, ParseStepKind(r.Text(row, 1)));
  s.kind = kind;
  s.pose = {r.Double(row, 2), r.Double(row, 3), r.Double(row, 4), r.Double(row, 5)};
  s.prompt = r.OptionalText(row, 6);
  s.prompt_kind = r.OptionalText(row, 7);
  s.expected_action = r.OptionalText(row, 8);
  if (!r.IsNull(row, 9)) {
    s.target =
        Directions{r.Double(row, 9), r.Double(row, 10), r.Double(row, 11), r.Double(row, 12)};
  }
  s.label = std::string(r.Text(row, 13));
  BRDF_ASSIGN_OR_RETURN(StepState state, ParseStepState(r.Text(row, 14)));
  s.state = state;
  s.note = r.OptionalText(row, 15);
  s.completed_at = r.OptionalDouble(row, 16);
  return s;
}

Result<ReadingRecord> ReadingAt(const PgResult& r, int row, std::int64_t session) {
  ReadingRecord g;
  g.id = r.Int64(row, 0);
  g.session_id = session;
  g.step_index = static_cast<int>(r.Int64(row, 1));
  BRDF_ASSIGN_OR_RETURN(ReadingKind kind, ParseReadingKind(r.Text(row, 2)));
  g.kind = kind;
  g.pose = {r.Double(row, 3), r.Double(row, 4), r.Double(row, 5), r.Double(row, 6)};
  g.directions = {r.Double(row, 7), r.Double(row, 8), r.Double(row, 9), r.Double(row, 10)};
  g.grid.start_nm = r.Double(row, 11);
  g.grid.step_nm = r.Double(row, 12);
  g.grid.count = static_cast<std::size_t>(r.Int64(row, 13));
  Result<std::vector<double>> spectrum = DecodeSpectrum(r.Bytes(row, 14), g.grid.count);
  if (!spectrum.ok()) {
    return spectrum.status().WithContext("archived reading " + std::to_string(g.id) + " of " +
                                         SessionName(session));
  }
  g.spectrum = std::move(*spectrum);
  g.quality_code = static_cast<int>(r.Int64(row, 15));
  g.flagged = r.Text(row, 16) == "t";
  g.integration_ms = static_cast<int>(r.Int64(row, 17));
  g.attempts = static_cast<int>(r.Int64(row, 18));
  g.note = std::string(r.Text(row, 19));
  g.reference_reading_id = r.OptionalInt64(row, 20);
  g.dark_reading_id = r.OptionalInt64(row, 21);
  g.meter_serial = std::string(r.Text(row, 22));
  g.recorded_at = r.Double(row, 23);
  if (r.IsNull(row, 24)) return g;  // not estimated
  const UncertaintyColumns columns{std::string(r.Text(row, 24)),
                                   r.Bytes(row, 25),
                                   r.Bytes(row, 26),
                                   r.Bytes(row, 27),
                                   std::string(r.Text(row, 28)),
                                   r.Bytes(row, 29),
                                   std::string(r.Text(row, 30))};
  Result<uncertainty::ReadingBudget> budget = DecodeUncertainty(columns, g.grid.count);
  if (!budget.ok()) {
    return budget.status().WithContext("archived reading " + std::to_string(g.id) + " of " +
                                       SessionName(session) + ": its uncertainty");
  }
  g.uncertainty = std::move(*budget);
  return g;
}

Result<ArchivedRound> RoundAt(const PgResult& r, int row, std::int64_t session) {
  ArchivedRound a;
  RoundRecord& g = a.record;
  g.session_id = session;
  g.round = static_cast<int>(r.Int64(row, 0));
  g.first_step = static_cast<int>(r.Int64(row, 1));
  g.step_count = static_cast<int>(r.Int64(row, 2));
  Result<std::vector<RoundPick>> picks = DecodePicks(r.Text(row, 3));
  if (!picks.ok()) {
    return picks.status().WithContext("archived round " + std::to_string(g.round) + " of " +
                                      SessionName(session));
  }
  g.picks = std::move(*picks);
  g.predicted_gain = r.Double(row, 4);
  g.uncertainty_left = r.Double(row, 5);
  g.readings_used = static_cast<int>(r.Int64(row, 6));
  g.created_at = r.Double(row, 7);
  a.spent_rig_s = r.Double(row, 8);
  a.spent_prompts = static_cast<int>(r.Int64(row, 9));
  a.rig_s = r.Double(row, 10);
  a.prompts = static_cast<int>(r.Int64(row, 11));
  return a;
}

Result<ReadingPointRecord> ReadingPointAt(const PgResult& r, int row, std::int64_t session) {
  ReadingPointRecord g;
  g.id = r.Int64(row, 0);
  Result<ReadingKind> kind = ParseReadingKind(r.Text(row, 1));
  if (!kind.ok()) {
    return kind.status().WithContext("archived reading " + std::to_string(g.id) + " of " +
                                     SessionName(session));
  }
  g.kind = *kind;
  g.pose = {r.Double(row, 2), r.Double(row, 3), r.Double(row, 4), r.Double(row, 5)};
  g.directions = {r.Double(row, 6), r.Double(row, 7), r.Double(row, 8), r.Double(row, 9)};
  g.flagged = r.Text(row, 10) == "t";
  return g;
}

}  // namespace

Result<std::shared_ptr<ArchiveReader>> ArchiveReader::Open(std::string conninfo) {
  std::shared_ptr<ArchiveReader> reader(new ArchiveReader(std::move(conninfo)));
  Status checked = reader->WithConnection([](PgConnection& conn) -> Status {
    BRDF_ASSIGN_OR_RETURN(int version, ArchiveVersion(conn));
    if (version != LatestArchiveVersion()) {
      return FailedPrecondition(
          "the archive has schema version " + std::to_string(version) + "; this brdf-archive " +
          "reads version " + std::to_string(LatestArchiveVersion()) +
          (version < LatestArchiveVersion()
               ? ": start a rig of this version with [archive] (it migrates the archive), or "
                 "run brdf-archive --migrate once with a role that may alter the schema"
               : ": upgrade brdf-archive"));
    }
    return Status::Ok();
  });
  if (!checked.ok()) return checked.WithContext("opening the archive");
  return reader;
}

Status ArchiveReader::WithConnection(const std::function<Status(PgConnection&)>& work) {
  for (int attempt = 0;; ++attempt) {
    std::unique_ptr<PgConnection> conn;
    {
      MutexLock lock(mu_);
      if (!idle_.empty()) {
        conn = std::move(idle_.back());
        idle_.pop_back();
      }
    }
    const bool reused = conn != nullptr;
    if (!conn) {
      BRDF_ASSIGN_OR_RETURN(std::unique_ptr<PgConnection> opened, PgConnection::Open(conninfo_));
      conn = std::move(opened);
    }
    Status st = work(*conn);
    if (conn->healthy()) {
      MutexLock lock(mu_);
      if (idle_.size() < kMaxIdleConnections) idle_.push_back(std::move(conn));
    }
    // A kept connection the server dropped since (restart, idle timeout): once more, afresh.
    if (st.code() == StatusCode::kDisconnected && reused && attempt == 0) continue;
    return st;
  }
}

Result<SessionRecord> ArchiveReader::GetSession(std::int64_t session) {
  Result<SessionRecord> out = NotFound("no " + SessionName(session) + " in the archive");
  BRDF_RETURN_IF_ERROR(WithConnection([&](PgConnection& conn) -> Status {
    BRDF_ASSIGN_OR_RETURN(PgResult r, conn.QueryPrepared("archive_session",
                                                         "SELECT " + std::string(kSessionColumns) +
                                                             " FROM sessions WHERE archive_id = $1",
                                                         PgParams().Add(session)));
    if (r.rows() == 1) out = SessionAt(r, 0);
    return Status::Ok();
  }));
  return out;
}

Result<std::vector<StepRecord>> ArchiveReader::GetSteps(std::int64_t session) {
  BRDF_RETURN_IF_ERROR(GetSession(session).status());
  std::vector<StepRecord> steps;
  BRDF_RETURN_IF_ERROR(WithConnection([&](PgConnection& conn) -> Status {
    BRDF_ASSIGN_OR_RETURN(
        PgResult r, conn.QueryPrepared("archive_steps", kStepsOfSession, PgParams().Add(session)));
    steps.clear();
    for (int i = 0; i < r.rows(); ++i) {
      BRDF_ASSIGN_OR_RETURN(StepRecord step, StepAt(r, i, session));
      steps.push_back(std::move(step));
    }
    return Status::Ok();
  }));
  return steps;
}

Result<std::vector<SessionEventRecord>> ArchiveReader::ListSessionEvents(std::int64_t session) {
  BRDF_RETURN_IF_ERROR(GetSession(session).status());
  std::vector<SessionEventRecord> events;
  BRDF_RETURN_IF_ERROR(WithConnection([&](PgConnection& conn) -> Status {
    BRDF_ASSIGN_OR_RETURN(PgResult r, conn.QueryPrepared("archive_events", kEventsOfSession,
                                                         PgParams().Add(session)));
    events.clear();
    for (int i = 0; i < r.rows(); ++i) {
      SessionEventRecord e;
      e.id = r.Int64(i, 0);
      e.session_id = session;
      e.at = r.Double(i, 1);
      Result<SessionState> state = ParseSessionState(std::string(r.Text(i, 2)));
      if (!state.ok()) {
        return state.status().WithContext("archived event " + std::to_string(e.id) + " of " +
                                          SessionName(session));
      }
      e.state = *state;
      e.reason = std::string(r.Text(i, 3));
      events.push_back(std::move(e));
    }
    return Status::Ok();
  }));
  return events;
}

Result<std::vector<DeviceRecord>> ArchiveReader::GetSessionDevices(std::int64_t session) {
  BRDF_RETURN_IF_ERROR(GetSession(session).status());
  std::vector<DeviceRecord> devices;
  BRDF_RETURN_IF_ERROR(WithConnection([&](PgConnection& conn) -> Status {
    BRDF_ASSIGN_OR_RETURN(PgResult r, conn.QueryPrepared("archive_devices", kDevicesOfSession,
                                                         PgParams().Add(session)));
    devices.clear();
    for (int i = 0; i < r.rows(); ++i) {
      devices.push_back(DeviceRecord{r.Int64(i, 0), session, std::string(r.Text(i, 1)),
                                     std::string(r.Text(i, 2)), std::string(r.Text(i, 3)),
                                     r.Double(i, 4)});
    }
    return Status::Ok();
  }));
  return devices;
}

Result<std::vector<ArchivedRound>> ArchiveReader::GetRounds(std::int64_t session) {
  BRDF_RETURN_IF_ERROR(GetSession(session).status());
  std::vector<ArchivedRound> rounds;
  BRDF_RETURN_IF_ERROR(WithConnection([&](PgConnection& conn) -> Status {
    BRDF_ASSIGN_OR_RETURN(PgResult r, conn.QueryPrepared("archive_rounds", kRoundsOfSession,
                                                         PgParams().Add(session)));
    rounds.clear();
    for (int i = 0; i < r.rows(); ++i) {
      BRDF_ASSIGN_OR_RETURN(ArchivedRound round, RoundAt(r, i, session));
      rounds.push_back(std::move(round));
    }
    return Status::Ok();
  }));
  return rounds;
}

template <typename Record>
Result<std::vector<Record>> ArchiveReader::ReadingPage(
    std::int64_t session, std::int64_t after_id, int limit, const char* statement,
    std::string_view query, Result<Record> (*read)(const PgResult&, int, std::int64_t)) {
  if (limit <= 0) {
    return InvalidArgument("reading the readings of " + SessionName(session) + ": limit " +
                           std::to_string(limit) + " must be positive");
  }
  std::vector<Record> readings;
  bool known = true;
  BRDF_RETURN_IF_ERROR(WithConnection([&](PgConnection& conn) -> Status {
    BRDF_ASSIGN_OR_RETURN(
        PgResult r,
        conn.QueryPrepared(statement, query, PgParams().Add(session).Add(after_id).Add(limit)));
    readings.clear();
    for (int i = 0; i < r.rows(); ++i) {
      BRDF_ASSIGN_OR_RETURN(Record reading, read(r, i, session));
      readings.push_back(std::move(reading));
    }
    if (readings.empty()) {  // none above after_id, or no such session
      BRDF_ASSIGN_OR_RETURN(PgResult s,
                            conn.QueryPrepared("archive_session_exists",
                                               "SELECT 1 FROM sessions WHERE archive_id = $1",
                                               PgParams().Add(session)));
      known = s.rows() == 1;
    }
    return Status::Ok();
  }));
  if (!known) return NotFound("no " + SessionName(session) + " in the archive");
  return readings;
}

Result<std::vector<ReadingRecord>> ArchiveReader::GetReadings(std::int64_t session,
                                                              std::int64_t after_id, int limit) {
  return ReadingPage<ReadingRecord>(session, after_id, limit, "archive_readings",
                                    kReadingsOfSession, &ReadingAt);
}

Result<std::vector<ReadingPointRecord>> ArchiveReader::GetReadingPoints(std::int64_t session,
                                                                        std::int64_t after_id,
                                                                        int limit) {
  return ReadingPage<ReadingPointRecord>(session, after_id, limit, "archive_reading_points",
                                         kReadingPointsOfSession, &ReadingPointAt);
}

Result<bool> ArchiveReader::Finished(std::int64_t session) {
  BRDF_ASSIGN_OR_RETURN(SessionRecord record, GetSession(session));
  if (!IsTerminal(record.state)) return false;
  bool finished = false;
  BRDF_RETURN_IF_ERROR(WithConnection([&](PgConnection& conn) -> Status {
    BRDF_ASSIGN_OR_RETURN(PgResult r, conn.QueryPrepared("archive_finished", R"sql(
SELECT (SELECT count(*) FROM steps WHERE session_uuid = $1 AND state = 'done'
          AND kind IN ('reference', 'dark', 'sample'))
     = (SELECT count(*) FROM readings WHERE session_uuid = $1)
)sql",
                                                         PgParams().Add(record.uuid)));
    finished = r.Text(0, 0) == "t";
    return Status::Ok();
  }));
  return finished;
}

Result<std::vector<SessionRecord>> ArchiveReader::ListSessions(const ArchiveSessionQuery& query) {
  if (query.limit <= 0) {
    return InvalidArgument("listing archived sessions: limit " + std::to_string(query.limit) +
                           " must be positive");
  }
  std::string sql = "SELECT " + std::string(kSessionColumns) + " FROM sessions WHERE true";
  PgParams params;
  int n = 0;
  auto next = [&n] { return "$" + std::to_string(++n); };
  if (!query.rig.empty()) {
    sql += " AND rig = " + next();
    params.Add(query.rig);
  }
  if (!query.sample.empty()) {
    const std::string p = next();
    sql += " AND (sample_id = " + p + " OR lower(sample_name) = lower(" + p + "))";
    params.Add(query.sample);
  }
  if (!query.material.empty()) {
    sql += " AND lower(material) = lower(" + next() + ")";
    params.Add(query.material);
  }
  if (!query.tag.empty()) {
    sql += " AND tags @> ARRAY[" + next() + "::text]";
    params.Add(query.tag);
  }
  if (!query.states.empty()) {
    sql += " AND state IN (";
    for (std::size_t i = 0; i < query.states.size(); ++i) {
      sql += (i == 0 ? "" : ", ") + next();
      params.Add(std::string(ToString(query.states[i])));
    }
    sql += ")";
  }
  if (query.created_after.has_value()) {
    sql += " AND created_at >= " + next();
    params.Add(*query.created_after);
  }
  if (query.created_before.has_value()) {
    sql += " AND created_at < " + next();
    params.Add(*query.created_before);
  }
  if (query.after.has_value()) {
    const std::string at = next();
    const std::string id = next();
    sql += " AND (created_at, archive_id) < (" + at + "::float8, " + id + "::bigint)";
    params.Add(query.after->first).Add(query.after->second);
  }
  sql += " ORDER BY created_at DESC, archive_id DESC LIMIT " + next();
  params.Add(query.limit);

  std::vector<SessionRecord> sessions;
  BRDF_RETURN_IF_ERROR(WithConnection([&](PgConnection& conn) -> Status {
    BRDF_ASSIGN_OR_RETURN(PgResult r, conn.Query(sql, params));
    sessions.clear();
    for (int i = 0; i < r.rows(); ++i) {
      BRDF_ASSIGN_OR_RETURN(SessionRecord s, SessionAt(r, i));
      sessions.push_back(std::move(s));
    }
    return Status::Ok();
  }));
  return sessions;
}

}  // namespace brdf::storage
