#include "storage/session_store.h"

#include <chrono>
#include <cmath>
#include <utility>

#include "core/spectrum.h"
#include "core/status.h"
#include "storage/round_picks.h"
#include "storage/schema.h"
#include "storage/session_rows.h"
#include "storage/spectrum_blob.h"
#include "storage/uncertainty_columns.h"
#include "storage/uuid.h"

namespace brdf::storage {
namespace {

// Readings fetched per page by ForEachReading: bounded memory (a PR-650 reading is ~1 KB).
constexpr int kReadingPage = 256;

std::string S(std::int64_t v) {
  return std::to_string(v);
}

std::string SessionName(std::int64_t session) {
  return "session " + S(session);
}
std::string StepName(std::int64_t session, int step) {
  return "step " + std::to_string(step) + " of session " + S(session);
}

// The session's state inside a transaction; kNotFound naming it when it does not exist.
Result<SessionState> SessionStateOf(Database& db, std::int64_t session) {
  BRDF_ASSIGN_OR_RETURN(Statement st, db.Prepare("SELECT state FROM sessions WHERE id = ?"));
  st.Bind(1, session);
  BRDF_ASSIGN_OR_RETURN(bool row, st.Step());
  if (!row) return NotFound("no " + SessionName(session) + " in the database");
  return FromColumn(ParseSessionState(st.Text(0)), db.path(), SessionName(session));
}

Status RequireSession(Database& db, std::int64_t session) {
  Result<SessionState> state = SessionStateOf(db, session);
  return state.ok() ? Status::Ok() : state.status();
}

// Refuses work on a session that has not started or has finished.
Status RequireStarted(std::int64_t session, SessionState state, std::string_view what) {
  if (state == SessionState::kQueued) {
    return FailedPrecondition(std::string(what) + ": " + SessionName(session) +
                              " is queued (not started); start it first");
  }
  if (IsTerminal(state)) {
    return FailedPrecondition(std::string(what) + ": " + SessionName(session) + " is " +
                              std::string(ToString(state)) + "; a finished session takes no more " +
                              "steps");
  }
  return Status::Ok();
}

struct StepRow {
  StepKind kind;
  StepState state;
};

// A step's kind and state inside a transaction; kNotFound naming it when it does not exist.
Result<StepRow> StepOf(Database& db, std::int64_t session, int step_index) {
  BRDF_ASSIGN_OR_RETURN(
      Statement st,
      db.Prepare("SELECT kind, state FROM steps WHERE session_id = ? AND step_index = ?"));
  st.Bind(1, session).Bind(2, step_index);
  BRDF_ASSIGN_OR_RETURN(bool row, st.Step());
  const std::string where = StepName(session, step_index);
  if (!row) {
    BRDF_ASSIGN_OR_RETURN(
        std::int64_t total,
        db.QueryInt64("SELECT total_steps FROM sessions WHERE id = " + S(session)));
    return NotFound("no " + where + " (its plan has " + S(total) + " steps, numbered 0 to " +
                    S(total - 1) + ")");
  }
  StepRow r{};
  BRDF_ASSIGN_OR_RETURN(r.kind, FromColumn(ParseStepKind(st.Text(0)), db.path(), where));
  BRDF_ASSIGN_OR_RETURN(r.state, FromColumn(ParseStepState(st.Text(1)), db.path(), where));
  return r;
}

// The refusal for a step that is no longer pending, saying what already happened to it.
Status NotPending(Database& db, std::int64_t session, int step_index, StepState state) {
  std::string m = StepName(session, step_index) + " is already " + std::string(ToString(state));
  Result<Statement> st =
      db.Prepare("SELECT id FROM readings WHERE session_id = ? AND step_index = ?");
  if (st.ok()) {
    st->Bind(1, session).Bind(2, step_index);
    Result<bool> row = st->Step();
    if (row.ok() && *row) m += " (reading " + S(st->Int64(0)) + ")";
  }
  return FailedPrecondition(m + "; nothing was written again");
}

// A reading named as reference or dark must be one of this session's, of that kind.
Status RequireLinkedReading(Database& db, std::int64_t session, std::optional<std::int64_t> id,
                            ReadingKind kind, std::string_view role) {
  if (!id.has_value()) return Status::Ok();
  BRDF_ASSIGN_OR_RETURN(Statement st,
                        db.Prepare("SELECT session_id, kind FROM readings WHERE id = ?"));
  st.Bind(1, *id);
  BRDF_ASSIGN_OR_RETURN(bool row, st.Step());
  const std::string what = std::string(role) + " reading " + S(*id);
  if (!row) return InvalidArgument(what + " does not exist");
  if (st.Int64(0) != session) {
    return InvalidArgument(what + " belongs to session " + S(st.Int64(0)) + ", not " +
                           SessionName(session));
  }
  if (st.Text(1) != ToString(kind)) {
    return InvalidArgument(what + " is a " + st.Text(1) + " reading, not a " +
                           std::string(ToString(kind)) + " reading");
  }
  return Status::Ok();
}

bool Finite(const Pose& p) {
  return std::isfinite(p.alpha) && std::isfinite(p.beta) && std::isfinite(p.gamma) &&
         std::isfinite(p.delta);
}
bool Finite(const Directions& d) {
  return std::isfinite(d.theta_i) && std::isfinite(d.phi_i) && std::isfinite(d.theta_o) &&
         std::isfinite(d.phi_o);
}

Status ValidateReading(const ReadingRecord& r) {
  if (!r.grid.valid()) {
    return InvalidArgument("the wavelength grid (start " + std::to_string(r.grid.start_nm) +
                           " nm, step " + std::to_string(r.grid.step_nm) + " nm, " +
                           std::to_string(r.grid.count) + " bands) is not valid");
  }
  if (r.spectrum.size() != r.grid.count) {
    return InvalidArgument("the spectrum has " + std::to_string(r.spectrum.size()) +
                           " values but its grid has " + std::to_string(r.grid.count) + " bands");
  }
  if (!Finite(r.pose)) return InvalidArgument("the pose has a non-finite angle");
  if (!Finite(r.directions)) return InvalidArgument("the directions have a non-finite angle");
  if (r.integration_ms < 0 || r.attempts < 0) {
    return InvalidArgument("integration_ms and attempts must not be negative");
  }
  return Status::Ok();
}

// The step is pending and takes a reading of this kind, and the reading's reference and dark
// readings are this session's.
Status RequireStepTakes(Database& db, std::int64_t session, int step_index,
                        const ReadingRecord& reading, const std::string& what) {
  BRDF_ASSIGN_OR_RETURN(StepRow step, StepOf(db, session, step_index));
  const std::optional<ReadingKind> expected = ReadingKindFor(step.kind);
  if (!expected.has_value()) {
    return InvalidArgument(what + ": it is a " + std::string(ToString(step.kind)) +
                           " step, which takes no reading; use CompleteStep");
  }
  if (*expected != reading.kind) {
    return InvalidArgument(what + ": it is a " + std::string(ToString(step.kind)) +
                           " step but the reading is a " + std::string(ToString(reading.kind)) +
                           " reading");
  }
  if (step.state != StepState::kPending) {
    return NotPending(db, session, step_index, step.state).WithContext(what);
  }
  BRDF_RETURN_IF_ERROR(RequireLinkedReading(db, session, reading.reference_reading_id,
                                            ReadingKind::kReference, "reference")
                           .WithContext(what));
  return RequireLinkedReading(db, session, reading.dark_reading_id, ReadingKind::kDark, "dark")
      .WithContext(what);
}

// A session holds one wavelength grid, its first reading's: a reading on another (a meter of
// another model put in mid-session) is refused, so every export and index of it has one grid.
Status RequireSessionGrid(Database& db, std::int64_t session, const ReadingRecord& reading,
                          const std::string& what) {
  BRDF_ASSIGN_OR_RETURN(Statement st,
                        db.Prepare("SELECT wl_start_nm, wl_step_nm, wl_count FROM readings "
                                   "WHERE session_id = ? ORDER BY id LIMIT 1"));
  st.Bind(1, session);
  BRDF_ASSIGN_OR_RETURN(bool row, st.Step());
  if (!row) return Status::Ok();
  const WavelengthGrid first{st.Double(0), st.Double(1), static_cast<std::size_t>(st.Int64(2))};
  if (first == reading.grid) return Status::Ok();
  return FailedPrecondition(what + ": the reading is on " + GridText(reading.grid) + " but " +
                            SessionName(session) + " holds readings on " + GridText(first) +
                            " (its first reading's); a session keeps one wavelength grid: "
                            "measure with a meter of that grid, or start a new session for this "
                            "meter");
}

// The reading's row (its spectrum encoded as `blob`).
Status InsertReading(Database& db, std::int64_t session, int step_index,
                     const ReadingRecord& reading, const std::vector<std::uint8_t>& blob,
                     UnixSeconds recorded_at, const std::string& what) {
  BRDF_ASSIGN_OR_RETURN(
      Statement st,
      db.Prepare(
          "INSERT INTO readings (session_id, step_index, kind, alpha, beta, gamma, delta, "
          "theta_i, phi_i, theta_o, phi_o, wl_start_nm, wl_step_nm, wl_count, spectrum, "
          "quality_code, flagged, integration_ms, attempts, note, reference_reading_id, "
          "dark_reading_id, meter_serial, recorded_at) "
          "VALUES (?, ?, ?, ?, ?, ?, ?, ?, ?, ?, ?, ?, ?, ?, ?, ?, ?, ?, ?, ?, ?, ?, ?, ?)"));
  st.Bind(1, session)
      .Bind(2, step_index)
      .Bind(3, ToString(reading.kind))
      .Bind(4, reading.pose.alpha)
      .Bind(5, reading.pose.beta)
      .Bind(6, reading.pose.gamma)
      .Bind(7, reading.pose.delta)
      .Bind(8, reading.directions.theta_i)
      .Bind(9, reading.directions.phi_i)
      .Bind(10, reading.directions.theta_o)
      .Bind(11, reading.directions.phi_o)
      .Bind(12, reading.grid.start_nm)
      .Bind(13, reading.grid.step_nm)
      .Bind(14, static_cast<std::int64_t>(reading.grid.count))
      .Bind(15, blob)
      .Bind(16, reading.quality_code)
      .Bind(17, reading.flagged)
      .Bind(18, reading.integration_ms)
      .Bind(19, reading.attempts)
      .Bind(20, reading.note)
      .Bind(21, reading.reference_reading_id)
      .Bind(22, reading.dark_reading_id)
      .Bind(23, reading.meter_serial)
      .Bind(24, recorded_at);
  return st.Run().WithContext(what);
}

// The reading's uncertainty budget in its columns, or nullopt when it has none (not estimated).
Result<std::optional<UncertaintyColumns>> UncertaintyOf(const ReadingRecord& r) {
  if (!r.uncertainty.has_value()) return std::optional<UncertaintyColumns>();
  if (r.kind != ReadingKind::kSample) {
    return InvalidArgument("only a sample reading has an uncertainty budget, not a " +
                           std::string(ToString(r.kind)) + " reading");
  }
  BRDF_ASSIGN_OR_RETURN(UncertaintyColumns columns,
                        EncodeUncertainty(*r.uncertainty, r.grid.count));
  return std::optional<UncertaintyColumns>(std::move(columns));
}

Status InsertUncertainty(Database& db, std::int64_t reading_id, std::size_t bands,
                         const UncertaintyColumns& u, const std::string& what) {
  BRDF_ASSIGN_OR_RETURN(
      Statement st,
      db.Prepare("INSERT INTO reading_uncertainty (reading_id, quantity, bands, value, combined, "
                 "independent, components, contributions, not_estimated) "
                 "VALUES (?, ?, ?, ?, ?, ?, ?, ?, ?)"));
  st.Bind(1, reading_id)
      .Bind(2, u.quantity)
      .Bind(3, static_cast<std::int64_t>(bands))
      .Bind(4, u.value)
      .Bind(5, u.combined)
      .Bind(6, u.independent)
      .Bind(7, u.components)
      .Bind(8, u.contributions)
      .Bind(9, u.not_estimated);
  return st.Run().WithContext(what + ": its uncertainty");
}

// The pending step done at `recorded_at`, and counted in the session's done_steps.
Status MarkStepDone(Database& db, std::int64_t session, int step_index, UnixSeconds recorded_at,
                    const std::string& what) {
  {
    BRDF_ASSIGN_OR_RETURN(
        Statement st, db.Prepare("UPDATE steps SET state = 'done', completed_at = ? "
                                 "WHERE session_id = ? AND step_index = ? AND state = 'pending'"));
    st.Bind(1, recorded_at).Bind(2, session).Bind(3, step_index);
    BRDF_RETURN_IF_ERROR(st.Run().WithContext(what + ": marking the step done"));
    if (db.changes() != 1) {
      return Internal(what + ": the step stopped being pending inside the transaction");
    }
  }
  BRDF_ASSIGN_OR_RETURN(Statement st,
                        db.Prepare("UPDATE sessions SET done_steps = done_steps + 1 WHERE id = ?"));
  st.Bind(1, session);
  return st.Run().WithContext(what + ": counting the step done");
}

// Steps to store: at least one, numbered first, first + 1, … in order, every angle finite.
Status CheckNewSteps(const std::vector<StepRecord>& steps, int first, const std::string& what) {
  if (steps.empty()) return InvalidArgument(what + ": the plan has no steps");
  for (std::size_t i = 0; i < steps.size(); ++i) {
    const int want = first + static_cast<int>(i);
    if (steps[i].step_index != want) {
      return InvalidArgument(what + ": step " + std::to_string(want) + " has step_index " +
                             std::to_string(steps[i].step_index) + "; steps must be numbered " +
                             std::to_string(first) + ", " + std::to_string(first + 1) +
                             ", … in order");
    }
    if (!Finite(steps[i].pose) || (steps[i].target && !Finite(*steps[i].target))) {
      return InvalidArgument(what + ": step " + std::to_string(want) + " has a non-finite angle");
    }
  }
  return Status::Ok();
}

// Inserts `steps` of `session` (inside the caller's transaction).
Status InsertSteps(Database& db, std::int64_t id, const std::vector<StepRecord>& steps,
                   const std::string& what) {
  BRDF_ASSIGN_OR_RETURN(
      Statement st,
      db.Prepare("INSERT INTO steps (session_id, step_index, kind, alpha, beta, gamma, delta, "
                 "prompt, prompt_kind, expected_action, target_theta_i, target_phi_i, "
                 "target_theta_o, target_phi_o, label) "
                 "VALUES (?, ?, ?, ?, ?, ?, ?, ?, ?, ?, ?, ?, ?, ?, ?)"));
  for (const StepRecord& step : steps) {
    const std::optional<Directions>& t = step.target;
    st.Bind(1, id)
        .Bind(2, step.step_index)
        .Bind(3, ToString(step.kind))
        .Bind(4, step.pose.alpha)
        .Bind(5, step.pose.beta)
        .Bind(6, step.pose.gamma)
        .Bind(7, step.pose.delta)
        .Bind(8, step.prompt)
        .Bind(9, step.prompt_kind)
        .Bind(10, step.expected_action)
        .Bind(11, t ? std::optional<double>(t->theta_i) : std::nullopt)
        .Bind(12, t ? std::optional<double>(t->phi_i) : std::nullopt)
        .Bind(13, t ? std::optional<double>(t->theta_o) : std::nullopt)
        .Bind(14, t ? std::optional<double>(t->phi_o) : std::nullopt)
        .Bind(15, step.label);
    BRDF_RETURN_IF_ERROR(st.Run().WithContext(what + ", step " + std::to_string(step.step_index)));
    st.Reset();
  }
  return Status::Ok();
}

}  // namespace

// --- Opening
// --------------------------------------------------------------------------------------

SessionStore::SessionStore(std::string path, Options options, std::unique_ptr<Database> writer)
    : path_(std::move(path)), options_(std::move(options)), writer_(std::move(writer)) {
  OpenOptions reader_options;
  reader_options.busy_timeout = options_.busy_timeout;
  readers_ = std::make_unique<ReaderPool>(path_, reader_options);
}

SessionStore::~SessionStore() = default;

Result<std::unique_ptr<SessionStore>> SessionStore::Open(const std::string& path, Options options) {
  OpenOptions open;
  open.busy_timeout = options.busy_timeout;
  BRDF_ASSIGN_OR_RETURN(std::unique_ptr<Database> db, Database::Open(path, open));
  BRDF_RETURN_IF_ERROR(Migrate(*db));
  if (options.max_database_bytes > 0) {
    BRDF_ASSIGN_OR_RETURN(std::int64_t page, db->QueryInt64("PRAGMA page_size"));
    const std::int64_t pages = std::max<std::int64_t>(1, options.max_database_bytes / page);
    BRDF_RETURN_IF_ERROR(db->Exec("PRAGMA max_page_count = " + S(pages)));
  }
  return std::unique_ptr<SessionStore>(new SessionStore(path, std::move(options), std::move(db)));
}

UnixSeconds SessionStore::Now() const {
  if (options_.wall_clock) return options_.wall_clock();
  return std::chrono::duration<double>(std::chrono::system_clock::now().time_since_epoch()).count();
}

// --- Sessions
// -------------------------------------------------------------------------------------

Result<std::int64_t> SessionStore::CreateSession(const NewSession& session,
                                                 const std::vector<StepRecord>& steps) {
  const std::string what = "creating session \"" + session.name + "\"";
  BRDF_RETURN_IF_ERROR(CheckNewSteps(steps, 0, what));
  const UnixSeconds now = Now();

  MutexLock lock(write_mu_);
  Database& db = *writer_;
  BRDF_ASSIGN_OR_RETURN(Transaction tx, Transaction::Begin(db));
  {
    BRDF_ASSIGN_OR_RETURN(
        Statement st,
        db.Prepare("INSERT INTO sessions (name, plan_kind, plan_json, state, created_at, "
                   "created_by_role, total_steps, white_reflectance, meter_serial, config_json, "
                   "uuid, rig) VALUES (?, ?, ?, 'queued', ?, ?, ?, ?, ?, ?, ?, ?)"));
    st.Bind(1, session.name)
        .Bind(2, session.plan_kind)
        .Bind(3, session.plan_json)
        .Bind(4, now)
        .Bind(5, session.created_by_role)
        .Bind(6, static_cast<std::int64_t>(steps.size()))
        .Bind(7, session.white_reflectance)
        .Bind(8, session.meter_serial)
        .Bind(9, session.config_json)
        .Bind(10, session.uuid.empty() ? NewUuid() : session.uuid)
        .Bind(11, session.rig);
    BRDF_RETURN_IF_ERROR(st.Run().WithContext(what));
  }
  const std::int64_t id = db.last_insert_rowid();
  BRDF_RETURN_IF_ERROR(InsertSteps(db, id, steps, what));
  BRDF_RETURN_IF_ERROR(tx.Commit().WithContext(what));
  return id;
}

Status SessionStore::AppendRound(const RoundRecord& round, const std::vector<StepRecord>& steps) {
  const std::int64_t id = round.session_id;
  const std::string what =
      "storing round " + std::to_string(round.round) + " of " + SessionName(id);
  BRDF_RETURN_IF_ERROR(CheckNewSteps(steps, round.first_step, what));
  const UnixSeconds now = Now();
  MutexLock lock(write_mu_);
  Database& db = *writer_;
  BRDF_ASSIGN_OR_RETURN(Transaction tx, Transaction::Begin(db));
  BRDF_ASSIGN_OR_RETURN(SessionState state, SessionStateOf(db, id));
  if (IsTerminal(state)) {
    return FailedPrecondition(what + ": the session has ended (" +
                              std::string(SessionStateName(state)) + ")");
  }
  BRDF_ASSIGN_OR_RETURN(std::int64_t total,
                        db.QueryInt64("SELECT total_steps FROM sessions WHERE id = " + S(id)));
  BRDF_ASSIGN_OR_RETURN(
      std::int64_t rounds,
      db.QueryInt64("SELECT count(*) FROM adaptive_rounds WHERE session_id = " + S(id)));
  if (round.round != rounds + 1 || round.first_step != total) {
    return FailedPrecondition(what + ": the session has " + S(rounds) + " round(s) and " +
                              S(total) + " steps; the next round is " + S(rounds + 1) +
                              " from step " + S(total) + " (not stored twice)");
  }
  BRDF_RETURN_IF_ERROR(InsertSteps(db, id, steps, what));
  BRDF_ASSIGN_OR_RETURN(Statement up,
                        db.Prepare("UPDATE sessions SET total_steps = ? WHERE id = ?"));
  up.Bind(1, total + static_cast<std::int64_t>(steps.size())).Bind(2, id);
  BRDF_RETURN_IF_ERROR(up.Run().WithContext(what));
  BRDF_ASSIGN_OR_RETURN(
      Statement st,
      db.Prepare("INSERT INTO adaptive_rounds (session_id, round, first_step, step_count, picks, "
                 "predicted_gain, uncertainty_left, readings_used, created_at) "
                 "VALUES (?, ?, ?, ?, ?, ?, ?, ?, ?)"));
  st.Bind(1, id)
      .Bind(2, round.round)
      .Bind(3, round.first_step)
      .Bind(4, static_cast<int>(steps.size()))
      .Bind(5, EncodePicks(round.picks))
      .Bind(6, round.predicted_gain)
      .Bind(7, round.uncertainty_left)
      .Bind(8, round.readings_used)
      .Bind(9, now);
  BRDF_RETURN_IF_ERROR(st.Run().WithContext(what));
  return tx.Commit().WithContext(what);
}

Result<std::vector<RoundRecord>> SessionStore::GetRounds(std::int64_t session) {
  BRDF_ASSIGN_OR_RETURN(ReaderPool::Lease db, readers_->Acquire());
  BRDF_ASSIGN_OR_RETURN(Transaction tx, Transaction::BeginRead(*db));
  BRDF_RETURN_IF_ERROR(RequireSession(*db, session));
  BRDF_ASSIGN_OR_RETURN(Statement st,
                        db->Prepare("SELECT " + std::string(kRoundColumns) +
                                    " FROM adaptive_rounds WHERE session_id = ? ORDER BY round"));
  st.Bind(1, session);
  std::vector<RoundRecord> out;
  while (true) {
    BRDF_ASSIGN_OR_RETURN(bool row, st.Step());
    if (!row) break;
    BRDF_ASSIGN_OR_RETURN(RoundRecord r, ReadRound(st));
    out.push_back(std::move(r));
  }
  return out;
}

Status SessionStore::SetSessionState(std::int64_t session, SessionState state, std::string reason) {
  const std::string what =
      "setting " + SessionName(session) + " to " + std::string(ToString(state));
  const UnixSeconds now = Now();

  MutexLock lock(write_mu_);
  Database& db = *writer_;
  BRDF_ASSIGN_OR_RETURN(Transaction tx, Transaction::Begin(db));
  BRDF_ASSIGN_OR_RETURN(SessionState current, SessionStateOf(db, session));
  if (IsTerminal(current)) {
    if (current == state) return Status::Ok();  // a retried call: already there
    return FailedPrecondition(what + ": it is already " + std::string(ToString(current)) +
                              "; a finished session does not change state");
  }
  if (state == SessionState::kQueued && current != SessionState::kQueued) {
    return FailedPrecondition(what + ": it is " + std::string(ToString(current)) +
                              "; a session that has started cannot be queued again");
  }
  if (state == SessionState::kCompleted) {
    BRDF_ASSIGN_OR_RETURN(Statement st, db.Prepare("SELECT count(*), min(step_index) FROM steps "
                                                   "WHERE session_id = ? AND state = 'pending'"));
    st.Bind(1, session);
    BRDF_ASSIGN_OR_RETURN(bool row, st.Step());
    if (row && st.Int64(0) > 0) {
      return FailedPrecondition(what + ": " + S(st.Int64(0)) +
                                " steps are still pending (the first is step " + S(st.Int64(1)) +
                                "); finish or skip them first");
    }
  }
  BRDF_ASSIGN_OR_RETURN(
      Statement st,
      db.Prepare("UPDATE sessions SET state = ?1, state_reason = ?2, state_changed_at = ?3, "
                 "started_at = CASE WHEN ?1 = 'running' AND started_at IS NULL THEN ?3 "
                 "ELSE started_at END, "
                 "finished_at = CASE WHEN ?4 THEN ?3 ELSE finished_at END WHERE id = ?5"));
  st.Bind(1, ToString(state))
      .Bind(2, reason)
      .Bind(3, now)
      .Bind(4, IsTerminal(state))
      .Bind(5, session);
  BRDF_RETURN_IF_ERROR(st.Run().WithContext(what));
  return tx.Commit().WithContext(what);
}

Status SessionStore::SetSessionMeterSerial(std::int64_t session, const std::string& meter_serial) {
  const std::string what = "recording the meter serial of " + SessionName(session);
  MutexLock lock(write_mu_);
  Database& db = *writer_;
  BRDF_ASSIGN_OR_RETURN(Statement st,
                        db.Prepare("UPDATE sessions SET meter_serial = ? WHERE id = ?"));
  st.Bind(1, meter_serial).Bind(2, session);
  BRDF_RETURN_IF_ERROR(st.Run().WithContext(what));
  if (db.changes() == 0) return NotFound("no " + SessionName(session) + " in the database");
  return Status::Ok();
}

Status SessionStore::AdoptUnnamedSessions(const std::string& rig) {
  MutexLock lock(write_mu_);
  Database& db = *writer_;
  BRDF_ASSIGN_OR_RETURN(Statement st, db.Prepare("UPDATE sessions SET rig = ? WHERE rig = ''"));
  st.Bind(1, rig);
  return st.Run().WithContext("naming the rig of sessions recorded before rig names");
}

Result<SessionRecord> SessionStore::GetSessionByUuid(const std::string& uuid) {
  BRDF_ASSIGN_OR_RETURN(ReaderPool::Lease db, readers_->Acquire());
  BRDF_ASSIGN_OR_RETURN(Statement st, db->Prepare("SELECT " + std::string(kSessionColumns) +
                                                  " FROM sessions WHERE uuid = ?"));
  st.Bind(1, uuid);
  BRDF_ASSIGN_OR_RETURN(bool row, st.Step());
  if (!row) return NotFound("no session with uuid " + uuid + " in " + path_);
  return ReadSession(st, path_);
}

Result<SessionRecord> SessionStore::GetSession(std::int64_t session) {
  BRDF_ASSIGN_OR_RETURN(ReaderPool::Lease db, readers_->Acquire());
  BRDF_ASSIGN_OR_RETURN(Statement st, db->Prepare("SELECT " + std::string(kSessionColumns) +
                                                  " FROM sessions WHERE id = ?"));
  st.Bind(1, session);
  BRDF_ASSIGN_OR_RETURN(bool row, st.Step());
  if (!row) return NotFound("no " + SessionName(session) + " in the database");
  return ReadSession(st, path_);
}

Result<std::vector<SessionRecord>> SessionStore::ListSessions() {
  BRDF_ASSIGN_OR_RETURN(ReaderPool::Lease db, readers_->Acquire());
  BRDF_ASSIGN_OR_RETURN(Statement st, db->Prepare("SELECT " + std::string(kSessionColumns) +
                                                  " FROM sessions ORDER BY id"));
  std::vector<SessionRecord> out;
  while (true) {
    BRDF_ASSIGN_OR_RETURN(bool row, st.Step());
    if (!row) break;
    BRDF_ASSIGN_OR_RETURN(SessionRecord s, ReadSession(st, path_));
    out.push_back(std::move(s));
  }
  return out;
}

Result<std::vector<std::int64_t>> SessionStore::RecoverInterruptedSessions() {
  const std::string what = "pausing sessions interrupted by a restart";
  MutexLock lock(write_mu_);
  Database& db = *writer_;
  BRDF_ASSIGN_OR_RETURN(Transaction tx, Transaction::Begin(db));
  constexpr std::string_view kInterrupted = "('running', 'pausing', 'awaiting_operator')";
  std::vector<std::int64_t> ids;
  {
    BRDF_ASSIGN_OR_RETURN(Statement st, db.Prepare("SELECT id FROM sessions WHERE state IN " +
                                                   std::string(kInterrupted) + " ORDER BY id"));
    while (true) {
      BRDF_ASSIGN_OR_RETURN(bool row, st.Step());
      if (!row) break;
      ids.push_back(st.Int64(0));
    }
  }
  if (ids.empty()) return ids;
  BRDF_ASSIGN_OR_RETURN(Statement st,
                        db.Prepare("UPDATE sessions SET state = 'paused', state_reason = ?, "
                                   "state_changed_at = ? WHERE state IN " +
                                   std::string(kInterrupted)));
  st.Bind(1, kRecoveredReason).Bind(2, Now());
  BRDF_RETURN_IF_ERROR(st.Run().WithContext(what));
  BRDF_RETURN_IF_ERROR(tx.Commit().WithContext(what));
  return ids;
}

// --- Steps
// ----------------------------------------------------------------------------------------

Result<std::vector<StepRecord>> SessionStore::GetSteps(std::int64_t session) {
  BRDF_ASSIGN_OR_RETURN(ReaderPool::Lease db, readers_->Acquire());
  BRDF_ASSIGN_OR_RETURN(Transaction tx, Transaction::BeginRead(*db));
  BRDF_RETURN_IF_ERROR(RequireSession(*db, session));
  BRDF_ASSIGN_OR_RETURN(Statement st,
                        db->Prepare("SELECT " + std::string(kStepColumns) +
                                    " FROM steps WHERE session_id = ? ORDER BY step_index"));
  st.Bind(1, session);
  std::vector<StepRecord> out;
  while (true) {
    BRDF_ASSIGN_OR_RETURN(bool row, st.Step());
    if (!row) break;
    BRDF_ASSIGN_OR_RETURN(StepRecord s, ReadStep(st, path_));
    out.push_back(std::move(s));
  }
  return out;
}

Result<std::vector<SessionEventRecord>> SessionStore::ListSessionEvents(std::int64_t session) {
  BRDF_ASSIGN_OR_RETURN(ReaderPool::Lease db, readers_->Acquire());
  BRDF_ASSIGN_OR_RETURN(Transaction tx, Transaction::BeginRead(*db));
  BRDF_RETURN_IF_ERROR(RequireSession(*db, session));
  BRDF_ASSIGN_OR_RETURN(Statement st,
                        db->Prepare("SELECT " + std::string(kEventColumns) +
                                    " FROM session_events WHERE session_id = ? ORDER BY id"));
  st.Bind(1, session);
  std::vector<SessionEventRecord> out;
  while (true) {
    BRDF_ASSIGN_OR_RETURN(bool row, st.Step());
    if (!row) break;
    BRDF_ASSIGN_OR_RETURN(SessionEventRecord e, ReadEvent(st, path_));
    out.push_back(std::move(e));
  }
  return out;
}

Result<std::optional<int>> SessionStore::FirstUnfinishedStep(std::int64_t session) {
  BRDF_ASSIGN_OR_RETURN(ReaderPool::Lease db, readers_->Acquire());
  BRDF_ASSIGN_OR_RETURN(Transaction tx, Transaction::BeginRead(*db));
  BRDF_RETURN_IF_ERROR(RequireSession(*db, session));
  BRDF_ASSIGN_OR_RETURN(Statement st, db->Prepare("SELECT min(step_index) FROM steps "
                                                  "WHERE session_id = ? AND state = 'pending'"));
  st.Bind(1, session);
  BRDF_ASSIGN_OR_RETURN(bool row, st.Step());
  if (!row || st.IsNull(0)) return std::optional<int>();
  return std::optional<int>(st.Int(0));
}

Result<std::int64_t> SessionStore::CompleteStepWithReading(std::int64_t session, int step_index,
                                                           const ReadingRecord& reading) {
  const std::string what = "storing the reading of " + StepName(session, step_index);
  if (Status valid = ValidateReading(reading); !valid.ok()) return valid.WithContext(what);
  const std::vector<std::uint8_t> blob = EncodeSpectrum(reading.spectrum);
  Result<std::optional<UncertaintyColumns>> uncertainty = UncertaintyOf(reading);
  if (!uncertainty.ok()) return uncertainty.status().WithContext(what);
  const UnixSeconds recorded_at = reading.recorded_at != 0 ? reading.recorded_at : Now();

  MutexLock lock(write_mu_);
  Database& db = *writer_;
  BRDF_ASSIGN_OR_RETURN(Transaction tx, Transaction::Begin(db));
  BRDF_ASSIGN_OR_RETURN(SessionState state, SessionStateOf(db, session));
  BRDF_RETURN_IF_ERROR(RequireStarted(session, state, what));
  BRDF_RETURN_IF_ERROR(RequireStepTakes(db, session, step_index, reading, what));
  BRDF_RETURN_IF_ERROR(RequireSessionGrid(db, session, reading, what));
  BRDF_RETURN_IF_ERROR(InsertReading(db, session, step_index, reading, blob, recorded_at, what));
  const std::int64_t id = db.last_insert_rowid();
  if (uncertainty->has_value()) {
    BRDF_RETURN_IF_ERROR(InsertUncertainty(db, id, reading.grid.count, **uncertainty, what));
  }
  BRDF_RETURN_IF_ERROR(MarkStepDone(db, session, step_index, recorded_at, what));
  BRDF_RETURN_IF_ERROR(tx.Commit().WithContext(what));
  return id;
}

namespace {

// The grid size of sample reading `reading` of `session`, or why it cannot take a budget.
Result<std::size_t> SampleBands(Database& db, std::int64_t session, std::int64_t reading,
                                const std::string& what) {
  BRDF_ASSIGN_OR_RETURN(
      Statement st,
      db.Prepare("SELECT kind, wl_count FROM readings WHERE id = ? AND session_id = ?"));
  st.Bind(1, reading).Bind(2, session);
  BRDF_ASSIGN_OR_RETURN(bool row, st.Step());
  const std::string name = "reading " + std::to_string(reading);
  if (!row) return NotFound(what + ": " + name + " is not one of the session's readings");
  if (st.Text(0) != ToString(ReadingKind::kSample)) {
    return InvalidArgument(what + ": " + name + " is a " + st.Text(0) +
                           " reading; only a sample reading has an uncertainty budget");
  }
  return static_cast<std::size_t>(st.Int64(1));
}

}  // namespace

Status SessionStore::ReplaceReadingUncertainties(
    std::int64_t session,
    const std::vector<std::pair<std::int64_t, uncertainty::ReadingBudget>>& budgets) {
  const std::string what =
      "replacing the uncertainty budgets of session " + std::to_string(session);
  MutexLock lock(write_mu_);
  Database& db = *writer_;
  BRDF_ASSIGN_OR_RETURN(Transaction tx, Transaction::Begin(db));
  BRDF_RETURN_IF_ERROR(SessionStateOf(db, session).status());
  for (const auto& [reading, budget] : budgets) {
    BRDF_ASSIGN_OR_RETURN(std::size_t bands, SampleBands(db, session, reading, what));
    Result<UncertaintyColumns> columns = EncodeUncertainty(budget, bands);
    if (!columns.ok()) {
      return columns.status().WithContext(what + ": reading " + std::to_string(reading));
    }
    BRDF_ASSIGN_OR_RETURN(Statement del,
                          db.Prepare("DELETE FROM reading_uncertainty WHERE reading_id = ?"));
    del.Bind(1, reading);
    BRDF_RETURN_IF_ERROR(del.Run().WithContext(what));
    BRDF_RETURN_IF_ERROR(InsertUncertainty(db, reading, bands, *columns, what));
  }
  // The archive has the budgets it was shipped with: it replaces them (ship_batch.h).
  BRDF_ASSIGN_OR_RETURN(
      Statement outbox,
      db.Prepare("INSERT INTO archive_outbox (session_id, step_index) SELECT ?, ? "
                 "WHERE (SELECT value FROM archive_marks WHERE name = 'enabled') = 1"));
  outbox.Bind(1, session).Bind(2, kOutboxBudgetsReplaced);
  BRDF_RETURN_IF_ERROR(outbox.Run().WithContext(what));
  return tx.Commit().WithContext(what);
}

Status SessionStore::CompleteStep(std::int64_t session, int step_index) {
  return MarkStepFinished(session, step_index, StepState::kDone, std::nullopt, false);
}

Status SessionStore::SkipStep(std::int64_t session, int step_index, std::string note) {
  return MarkStepFinished(session, step_index, StepState::kSkipped, std::move(note), true);
}

Status SessionStore::MarkStepFinished(std::int64_t session, int step_index, StepState state,
                                      std::optional<std::string> note, bool measuring_allowed) {
  const std::string what = std::string(state == StepState::kDone ? "completing " : "skipping ") +
                           StepName(session, step_index);
  const UnixSeconds now = Now();

  MutexLock lock(write_mu_);
  Database& db = *writer_;
  BRDF_ASSIGN_OR_RETURN(Transaction tx, Transaction::Begin(db));
  BRDF_ASSIGN_OR_RETURN(SessionState session_state, SessionStateOf(db, session));
  if (state == StepState::kDone) {
    BRDF_RETURN_IF_ERROR(RequireStarted(session, session_state, what));
  } else if (IsTerminal(session_state)) {
    return FailedPrecondition(what + ": " + SessionName(session) + " is " +
                              std::string(ToString(session_state)));
  }
  BRDF_ASSIGN_OR_RETURN(StepRow step, StepOf(db, session, step_index));
  if (!measuring_allowed && ReadingKindFor(step.kind).has_value()) {
    return InvalidArgument(what + ": it is a " + std::string(ToString(step.kind)) +
                           " step; it completes with its reading (CompleteStepWithReading) or is "
                           "skipped (SkipStep)");
  }
  if (step.state != StepState::kPending) {
    return NotPending(db, session, step_index, step.state).WithContext(what);
  }
  {
    BRDF_ASSIGN_OR_RETURN(
        Statement st, db.Prepare("UPDATE steps SET state = ?, note = ?, completed_at = ? "
                                 "WHERE session_id = ? AND step_index = ? AND state = 'pending'"));
    st.Bind(1, ToString(state)).Bind(2, note).Bind(3, now).Bind(4, session).Bind(5, step_index);
    BRDF_RETURN_IF_ERROR(st.Run().WithContext(what));
  }
  {
    BRDF_ASSIGN_OR_RETURN(
        Statement st, db.Prepare("UPDATE sessions SET done_steps = done_steps + 1 WHERE id = ?"));
    st.Bind(1, session);
    BRDF_RETURN_IF_ERROR(st.Run().WithContext(what));
  }
  return tx.Commit().WithContext(what);
}

// --- Readings
// -------------------------------------------------------------------------------------

namespace {

// A page of `session`'s readings with id > after_id, ascending, each row (`columns`) turned into a
// Record by `read`: GetReadings and GetReadingPoints.
template <typename Record>
Result<std::vector<Record>> ReadingPage(ReaderPool& readers, const std::string& path,
                                        std::int64_t session, std::int64_t after_id, int limit,
                                        std::string_view columns, std::string_view from,
                                        Result<Record> (*read)(const Statement&,
                                                               const std::string&)) {
  if (limit <= 0) {
    return InvalidArgument("reading the readings of " + SessionName(session) + ": limit " +
                           std::to_string(limit) + " must be positive");
  }
  BRDF_ASSIGN_OR_RETURN(ReaderPool::Lease db, readers.Acquire());
  BRDF_ASSIGN_OR_RETURN(Transaction tx, Transaction::BeginRead(*db));
  BRDF_RETURN_IF_ERROR(RequireSession(*db, session));
  BRDF_ASSIGN_OR_RETURN(
      Statement st, db->Prepare("SELECT " + std::string(columns) + " FROM " + std::string(from) +
                                " WHERE session_id = ? AND id > ? ORDER BY id LIMIT ?"));
  st.Bind(1, session).Bind(2, after_id).Bind(3, limit);
  std::vector<Record> out;
  while (true) {
    BRDF_ASSIGN_OR_RETURN(bool row, st.Step());
    if (!row) break;
    BRDF_ASSIGN_OR_RETURN(Record r, read(st, path));
    out.push_back(std::move(r));
  }
  return out;
}

}  // namespace

Result<std::vector<ReadingRecord>> SessionStore::GetReadings(std::int64_t session,
                                                             std::int64_t after_id, int limit) {
  return ReadingPage<ReadingRecord>(*readers_, path_, session, after_id, limit, kReadingColumns,
                                    kReadingsWithUncertainty, &ReadReading);
}

Result<std::vector<ReadingPointRecord>> SessionStore::GetReadingPoints(std::int64_t session,
                                                                       std::int64_t after_id,
                                                                       int limit) {
  return ReadingPage<ReadingPointRecord>(*readers_, path_, session, after_id, limit,
                                         kReadingPointColumns, "readings", &ReadReadingPoint);
}

Result<ReadingRecord> SessionStore::GetReading(std::int64_t reading_id) {
  BRDF_ASSIGN_OR_RETURN(ReaderPool::Lease db, readers_->Acquire());
  BRDF_ASSIGN_OR_RETURN(Statement st,
                        db->Prepare("SELECT " + std::string(kReadingColumns) + " FROM " +
                                    std::string(kReadingsWithUncertainty) + " WHERE id = ?"));
  st.Bind(1, reading_id);
  BRDF_ASSIGN_OR_RETURN(bool row, st.Step());
  if (!row) return NotFound("no reading " + S(reading_id) + " in the database");
  return ReadReading(st, path_);
}

Status SessionStore::ForEachReading(std::int64_t session,
                                    const std::function<Status(const ReadingRecord&)>& visit) {
  std::int64_t after = 0;
  while (true) {
    BRDF_ASSIGN_OR_RETURN(std::vector<ReadingRecord> page,
                          GetReadings(session, after, kReadingPage));
    for (const ReadingRecord& r : page) BRDF_RETURN_IF_ERROR(visit(r));
    if (page.size() < static_cast<std::size_t>(kReadingPage)) return Status::Ok();
    after = page.back().id;
  }
}

Result<int> SessionStore::CountReadings(std::int64_t session) {
  BRDF_ASSIGN_OR_RETURN(ReaderPool::Lease db, readers_->Acquire());
  BRDF_ASSIGN_OR_RETURN(Transaction tx, Transaction::BeginRead(*db));
  BRDF_RETURN_IF_ERROR(RequireSession(*db, session));
  BRDF_ASSIGN_OR_RETURN(
      std::int64_t n,
      db->QueryInt64("SELECT count(*) FROM readings WHERE session_id = " + S(session)));
  return static_cast<int>(n);
}

// --- Devices and audit
// ----------------------------------------------------------------------------

Status SessionStore::RecordDevice(const DeviceRecord& device) {
  const std::string what =
      "recording " + device.kind + " " + device.model + " serial \"" + device.serial + "\"";
  if (device.kind.empty() || device.model.empty()) {
    return InvalidArgument(what + ": a device needs a kind and a model");
  }
  const UnixSeconds first_seen = device.first_seen != 0 ? device.first_seen : Now();
  MutexLock lock(write_mu_);
  BRDF_ASSIGN_OR_RETURN(
      Statement st,
      writer_->Prepare("INSERT INTO devices (session_id, kind, model, serial, first_seen) "
                       "VALUES (?, ?, ?, ?, ?) ON CONFLICT DO NOTHING"));
  st.Bind(1, device.session_id)
      .Bind(2, device.kind)
      .Bind(3, device.model)
      .Bind(4, device.serial)
      .Bind(5, first_seen);
  return st.Run().WithContext(what);
}

Result<std::vector<DeviceRecord>> SessionStore::GetDevices(std::optional<std::int64_t> session) {
  BRDF_ASSIGN_OR_RETURN(ReaderPool::Lease db, readers_->Acquire());
  BRDF_ASSIGN_OR_RETURN(
      Statement st, db->Prepare("SELECT id, session_id, kind, model, serial, first_seen "
                                "FROM devices WHERE ?1 IS NULL OR session_id = ?1 ORDER BY id"));
  st.Bind(1, session);
  std::vector<DeviceRecord> out;
  while (true) {
    BRDF_ASSIGN_OR_RETURN(bool row, st.Step());
    if (!row) break;
    out.push_back(DeviceRecord{st.Int64(0), st.OptionalInt64(1), st.Text(2), st.Text(3), st.Text(4),
                               st.Double(5)});
  }
  return out;
}

Status SessionStore::AppendAudit(const AuditRecord& entry) {
  const std::string what = "appending audit entry \"" + entry.action + "\" by " + entry.actor;
  if (entry.actor.empty() || entry.action.empty()) {
    return InvalidArgument(what + ": an audit entry needs an actor and an action");
  }
  const UnixSeconds at = entry.at != 0 ? entry.at : Now();
  MutexLock lock(write_mu_);
  BRDF_ASSIGN_OR_RETURN(Statement st,
                        writer_->Prepare("INSERT INTO audit (at, role, actor, action, session_id, "
                                         "detail) VALUES (?, ?, ?, ?, ?, ?)"));
  st.Bind(1, at)
      .Bind(2, entry.role)
      .Bind(3, entry.actor)
      .Bind(4, entry.action)
      .Bind(5, entry.session_id)
      .Bind(6, entry.detail);
  return st.Run().WithContext(what);
}

Result<std::vector<AuditRecord>> SessionStore::GetAudit(std::optional<std::int64_t> session,
                                                        int limit) {
  if (limit <= 0) {
    return InvalidArgument("reading the audit: limit " + std::to_string(limit) +
                           " must be positive");
  }
  BRDF_ASSIGN_OR_RETURN(ReaderPool::Lease db, readers_->Acquire());
  BRDF_ASSIGN_OR_RETURN(
      Statement st,
      db->Prepare(session.has_value()
                      ? "SELECT id, at, role, actor, action, session_id, detail FROM audit "
                        "WHERE session_id = ?1 ORDER BY id DESC LIMIT ?2"
                      : "SELECT id, at, role, actor, action, session_id, detail FROM audit "
                        "ORDER BY id DESC LIMIT ?2"));
  if (session.has_value()) st.Bind(1, *session);
  st.Bind(2, limit);
  std::vector<AuditRecord> out;
  while (true) {
    BRDF_ASSIGN_OR_RETURN(bool row, st.Step());
    if (!row) break;
    out.push_back(AuditRecord{st.Int64(0), st.Double(1), st.Text(2), st.Text(3), st.Text(4),
                              st.OptionalInt64(5), st.Text(6)});
  }
  return out;
}

}  // namespace brdf::storage
