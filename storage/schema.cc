#include "storage/schema.h"

#include <array>
#include <cstdio>
#include <string>

namespace brdf::storage {
namespace {

// Version 1: everything. Kept verbatim once released; later changes are new migrations.
constexpr std::string_view kV1 = R"sql(
CREATE TABLE sessions (
  id                INTEGER PRIMARY KEY,
  name              TEXT    NOT NULL,
  plan_kind         TEXT    NOT NULL,
  plan_json         TEXT    NOT NULL,
  state             TEXT    NOT NULL DEFAULT 'queued' CHECK (state IN ('queued', 'running',
                      'pausing', 'paused', 'awaiting_operator', 'completed', 'aborted', 'failed')),
  state_reason      TEXT    NOT NULL DEFAULT '',
  created_at        REAL    NOT NULL,
  started_at        REAL,
  finished_at       REAL,
  created_by_role   TEXT    NOT NULL DEFAULT '',
  total_steps       INTEGER NOT NULL CHECK (total_steps >= 0),
  done_steps        INTEGER NOT NULL DEFAULT 0
                      CHECK (done_steps >= 0 AND done_steps <= total_steps),
  white_reflectance REAL,
  meter_serial      TEXT    NOT NULL DEFAULT '',
  config_json       TEXT    NOT NULL DEFAULT '{}'
);
CREATE INDEX sessions_by_state ON sessions (state);

CREATE TABLE steps (
  session_id      INTEGER NOT NULL REFERENCES sessions (id),
  step_index      INTEGER NOT NULL CHECK (step_index >= 0),
  kind            TEXT    NOT NULL
                    CHECK (kind IN ('move', 'prompt', 'reference', 'dark', 'sample')),
  alpha           REAL    NOT NULL,
  beta            REAL    NOT NULL,
  gamma           REAL    NOT NULL,
  delta           REAL    NOT NULL,
  prompt          TEXT,
  prompt_kind     TEXT,
  expected_action TEXT,
  target_theta_i  REAL,
  target_phi_i    REAL,
  target_theta_o  REAL,
  target_phi_o    REAL,
  label           TEXT    NOT NULL DEFAULT '',
  state           TEXT    NOT NULL DEFAULT 'pending'
                    CHECK (state IN ('pending', 'done', 'skipped')),
  note            TEXT,
  completed_at    REAL,
  PRIMARY KEY (session_id, step_index),
  CHECK ((target_theta_i IS NULL) = (target_phi_i IS NULL) AND
         (target_theta_i IS NULL) = (target_theta_o IS NULL) AND
         (target_theta_i IS NULL) = (target_phi_o IS NULL))
) WITHOUT ROWID;
-- Where a session resumes: the first pending step, found without scanning finished ones.
CREATE INDEX steps_pending ON steps (session_id, step_index) WHERE state = 'pending';

CREATE TABLE readings (
  id                   INTEGER PRIMARY KEY,
  session_id           INTEGER NOT NULL REFERENCES sessions (id),
  step_index           INTEGER NOT NULL,
  kind                 TEXT    NOT NULL CHECK (kind IN ('sample', 'reference', 'dark')),
  alpha                REAL    NOT NULL,
  beta                 REAL    NOT NULL,
  gamma                REAL    NOT NULL,
  delta                REAL    NOT NULL,
  theta_i              REAL    NOT NULL,
  phi_i                REAL    NOT NULL,
  theta_o              REAL    NOT NULL,
  phi_o                REAL    NOT NULL,
  wl_start_nm          REAL    NOT NULL,
  wl_step_nm           REAL    NOT NULL CHECK (wl_step_nm > 0),
  wl_count             INTEGER NOT NULL CHECK (wl_count > 0),
  spectrum             BLOB    NOT NULL
                         CHECK (typeof(spectrum) = 'blob' AND length(spectrum) = 8 * wl_count),
  quality_code         INTEGER NOT NULL DEFAULT 0,
  flagged              INTEGER NOT NULL DEFAULT 0 CHECK (flagged IN (0, 1)),
  integration_ms       INTEGER NOT NULL DEFAULT 0 CHECK (integration_ms >= 0),
  attempts             INTEGER NOT NULL DEFAULT 1 CHECK (attempts >= 0),
  note                 TEXT    NOT NULL DEFAULT '',
  reference_reading_id INTEGER REFERENCES readings (id),
  dark_reading_id      INTEGER REFERENCES readings (id),
  meter_serial         TEXT    NOT NULL DEFAULT '',
  recorded_at          REAL    NOT NULL,
  -- One reading per step, enforced by the database itself: a retried write cannot duplicate.
  UNIQUE (session_id, step_index),
  FOREIGN KEY (session_id, step_index) REFERENCES steps (session_id, step_index)
);
-- Streaming a session's readings in id order.
CREATE INDEX readings_by_session ON readings (session_id, id);

CREATE TABLE devices (
  id         INTEGER PRIMARY KEY,
  session_id INTEGER REFERENCES sessions (id),
  kind       TEXT    NOT NULL,
  model      TEXT    NOT NULL,
  serial     TEXT    NOT NULL,
  first_seen REAL    NOT NULL
);
-- A device is recorded once per session (or once at daemon level when session_id is NULL).
CREATE UNIQUE INDEX devices_identity ON devices (ifnull(session_id, 0), kind, model, serial);

CREATE TABLE audit (
  id         INTEGER PRIMARY KEY,
  at         REAL    NOT NULL,
  role       TEXT    NOT NULL,
  actor      TEXT    NOT NULL,
  action     TEXT    NOT NULL,
  session_id INTEGER REFERENCES sessions (id),
  detail     TEXT    NOT NULL DEFAULT ''
);
CREATE INDEX audit_by_session ON audit (session_id, id) WHERE session_id IS NOT NULL;
)sql";

// Version 2: global identity. Every session gets a random (version 4) UUID -- existing ones get
// theirs here -- and the name of the rig that recorded it ('' until the daemon adopts them).
constexpr std::string_view kV2 = R"sql(
ALTER TABLE sessions ADD COLUMN uuid TEXT;
ALTER TABLE sessions ADD COLUMN rig TEXT NOT NULL DEFAULT '';
UPDATE sessions SET uuid =
  lower(hex(randomblob(4))) || '-' || lower(hex(randomblob(2))) || '-4' ||
  substr(lower(hex(randomblob(2))), 2) || '-' || substr('89ab', 1 + (abs(random()) % 4), 1) ||
  substr(lower(hex(randomblob(2))), 2) || '-' || lower(hex(randomblob(6)))
  WHERE uuid IS NULL;
CREATE UNIQUE INDEX sessions_by_uuid ON sessions (uuid);
)sql";

// Version 3: shipping to the lab archive. Triggers note every session and step change in an
// outbox, in the same transaction as the change, while shipping is on (archive_marks 'enabled');
// readings, devices and audit entries are shipped by id above their high-water mark.
constexpr std::string_view kV3 = R"sql(
CREATE TABLE archive_outbox (
  seq        INTEGER PRIMARY KEY,
  session_id INTEGER NOT NULL,
  step_index INTEGER
);
CREATE TABLE archive_marks (
  name  TEXT PRIMARY KEY,
  value INTEGER NOT NULL
) WITHOUT ROWID;
INSERT INTO archive_marks (name, value)
  VALUES ('enabled', 0), ('readings', 0), ('devices', 0), ('audit', 0);
CREATE TRIGGER archive_session_created AFTER INSERT ON sessions
  WHEN (SELECT value FROM archive_marks WHERE name = 'enabled') = 1
  BEGIN INSERT INTO archive_outbox (session_id, step_index) VALUES (NEW.id, -1); END;
CREATE TRIGGER archive_session_changed AFTER UPDATE ON sessions
  WHEN (SELECT value FROM archive_marks WHERE name = 'enabled') = 1
  BEGIN INSERT INTO archive_outbox (session_id, step_index) VALUES (NEW.id, NULL); END;
CREATE TRIGGER archive_step_changed AFTER UPDATE ON steps
  WHEN (SELECT value FROM archive_marks WHERE name = 'enabled') = 1
  BEGIN INSERT INTO archive_outbox (session_id, step_index) VALUES (NEW.session_id, NEW.step_index);
  END;
)sql";

// Version 4: the events history. Triggers append an event to session_events whenever a session is
// created or its state or reason changes -- whoever writes it (the store, start-up recovery, a
// hand-run UPDATE) -- in the same transaction as the change. brdfd stamps the time of a change in
// sessions.state_changed_at; a change made without it gets SQLite's clock. Existing sessions get
// one event each: their current state, at their last known time. Events ship to the archive by id
// above the 'events' mark.
constexpr std::string_view kV4 = R"sql(
ALTER TABLE sessions ADD COLUMN state_changed_at REAL;
CREATE TABLE session_events (
  id         INTEGER PRIMARY KEY,
  session_id INTEGER NOT NULL REFERENCES sessions (id),
  at         REAL    NOT NULL,
  state      TEXT    NOT NULL CHECK (state IN ('queued', 'running', 'pausing', 'paused',
               'awaiting_operator', 'completed', 'aborted', 'failed')),
  reason     TEXT    NOT NULL DEFAULT ''
);
CREATE INDEX session_events_by_session ON session_events (session_id, id);
INSERT INTO session_events (session_id, at, state, reason)
  SELECT id, coalesce(finished_at, started_at, created_at), state, state_reason
  FROM sessions ORDER BY id;
CREATE TRIGGER session_event_created AFTER INSERT ON sessions
  BEGIN INSERT INTO session_events (session_id, at, state, reason)
    VALUES (NEW.id, NEW.created_at, NEW.state, NEW.state_reason); END;
CREATE TRIGGER session_event_changed AFTER UPDATE OF state, state_reason ON sessions
  WHEN NEW.state IS NOT OLD.state OR NEW.state_reason IS NOT OLD.state_reason
  BEGIN INSERT INTO session_events (session_id, at, state, reason)
    VALUES (NEW.id, CASE WHEN NEW.state_changed_at IS NOT OLD.state_changed_at
                         THEN NEW.state_changed_at
                         ELSE (julianday('now') - 2440587.5) * 86400.0 END,
            NEW.state, NEW.state_reason); END;
INSERT INTO archive_marks (name, value) VALUES ('events', 0);
)sql";

// Version 5: each reading's uncertainty budget (docs/uncertainty.md), a row per reading that has
// one, written in the same transaction as the reading. A reading without a row -- every reading
// stored before version 5, and darks and references -- is "not estimated", never zero. The blobs
// are little-endian float64 per band like the spectrum (uncertainty_columns.h); `bands` repeats the
// reading's wl_count so that the CHECKs can hold the lengths.
constexpr std::string_view kV5 = R"sql(
CREATE TABLE reading_uncertainty (
  reading_id    INTEGER PRIMARY KEY REFERENCES readings (id),
  quantity      TEXT    NOT NULL CHECK (quantity IN ('brdf', 'reflectance')),
  bands         INTEGER NOT NULL CHECK (bands > 0),
  value         BLOB    NOT NULL CHECK (length(value) = 8 * bands),
  combined      BLOB    NOT NULL CHECK (length(combined) = 8 * bands),
  independent   BLOB    NOT NULL CHECK (length(independent) = 8 * bands),
  components    TEXT    NOT NULL,
  contributions BLOB    NOT NULL CHECK (length(contributions) % (8 * bands) = 0),
  not_estimated TEXT    NOT NULL DEFAULT ''
);
)sql";

// Version 6: the rounds of adaptive sessions (docs/adaptive.md), each stored with its steps in one
// transaction before it is measured: the poses chosen (one line "alpha beta gamma delta gain" per
// pick, model angles in degrees), the predicted gain, the uncertainty left when it was chosen and
// the number of sample readings it was chosen from. Steps appended to a session after it was
// created are noted in the archive's outbox (only steps beyond the session's total at the time,
// so that a new session's steps are not noted twice).
constexpr std::string_view kV6 = R"sql(
CREATE TABLE adaptive_rounds (
  session_id       INTEGER NOT NULL REFERENCES sessions (id),
  round            INTEGER NOT NULL CHECK (round >= 1),
  first_step       INTEGER NOT NULL CHECK (first_step >= 0),
  step_count       INTEGER NOT NULL CHECK (step_count >= 1),
  picks            TEXT    NOT NULL,
  predicted_gain   REAL    NOT NULL,
  uncertainty_left REAL    NOT NULL,
  readings_used    INTEGER NOT NULL CHECK (readings_used >= 0),
  created_at       REAL    NOT NULL,
  PRIMARY KEY (session_id, round)
) WITHOUT ROWID;
CREATE TRIGGER archive_step_appended AFTER INSERT ON steps
  WHEN (SELECT value FROM archive_marks WHERE name = 'enabled') = 1 AND
       NEW.step_index >= (SELECT total_steps FROM sessions WHERE id = NEW.session_id)
  BEGIN INSERT INTO archive_outbox (session_id, step_index) VALUES (NEW.session_id, NEW.step_index);
  END;
)sql";

constexpr std::array<Migration, 6> kMigrations{{
    {1, "create sessions, steps, readings, devices and audit", kV1},
    {2, "give every session a UUID and its rig's name", kV2},
    {3, "keep an outbox and marks for shipping to the lab archive", kV3},
    {4, "keep every session's history of states (session_events)", kV4},
    {5, "keep each reading's uncertainty budget (reading_uncertainty)", kV5},
    {6, "keep the rounds of adaptive sessions (adaptive_rounds)", kV6},
}};

std::string Hex(std::int64_t v) {
  char buf[32];
  std::snprintf(buf, sizeof buf, "0x%llx", static_cast<unsigned long long>(v));
  return buf;
}

}  // namespace

std::span<const Migration> SchemaMigrations() {
  return kMigrations;
}

int LatestSchemaVersion() {
  return kMigrations.back().version;
}

Result<int> SchemaVersion(Database& db) {
  BRDF_ASSIGN_OR_RETURN(std::int64_t v, db.QueryInt64("PRAGMA user_version"));
  return static_cast<int>(v);
}

Status Migrate(Database& db, std::span<const Migration> migrations) {
  for (std::size_t i = 0; i < migrations.size(); ++i) {
    if (migrations[i].version != static_cast<int>(i) + 1) {
      return Internal("schema migrations must be numbered 1, 2, 3, …; entry " + std::to_string(i) +
                      " has version " + std::to_string(migrations[i].version) +
                      " (a bug in brdfd's storage)");
    }
  }
  const int latest = static_cast<int>(migrations.size());

  // Looks at the file; refuses (touching nothing) what this build must not modify.
  auto check = [&](int version) -> Status {
    BRDF_ASSIGN_OR_RETURN(std::int64_t app, db.QueryInt64("PRAGMA application_id"));
    BRDF_ASSIGN_OR_RETURN(std::int64_t objects,
                          db.QueryInt64("SELECT count(*) FROM sqlite_schema"));
    if (app != kApplicationId && (app != 0 || version != 0 || objects != 0)) {
      return FailedPrecondition(
          db.path() + " is not a brdfd database (application_id " + Hex(app) + ", schema version " +
          std::to_string(version) + ", " + std::to_string(objects) +
          " schema objects): point brdfd at a new or brdfd-made database file");
    }
    if (version > latest) {
      return FailedPrecondition(
          db.path() + " has schema version " + std::to_string(version) +
          ", newer than the latest this brdfd knows (" + std::to_string(latest) +
          "): it was written by a newer brdfd. Run that newer brdfd, or point this one at another "
          "database file; do not edit the version by hand");
    }
    return Status::Ok();
  };

  BRDF_ASSIGN_OR_RETURN(int version, SchemaVersion(db));
  BRDF_RETURN_IF_ERROR(check(version));
  if (version == latest) return Status::Ok();

  for (const Migration& m : migrations) {
    if (m.version <= version) continue;
    const std::string what = "migrating " + db.path() + " to schema version " +
                             std::to_string(m.version) + " (" + std::string(m.description) + ")";
    Result<Transaction> tx = Transaction::Begin(db);
    if (!tx.ok()) return tx.status().WithContext(what);
    // Another process may have migrated between our look and our write lock: look again.
    Result<int> now = SchemaVersion(db);
    if (!now.ok()) return now.status().WithContext(what);
    BRDF_RETURN_IF_ERROR(check(*now));
    if (*now >= m.version) continue;
    BRDF_RETURN_IF_ERROR(db.Exec(m.sql).WithContext(what));
    BRDF_RETURN_IF_ERROR(db.Exec("PRAGMA user_version = " + std::to_string(m.version) +
                                 "; PRAGMA application_id = " + std::to_string(kApplicationId))
                             .WithContext(what));
    BRDF_RETURN_IF_ERROR(tx->Commit().WithContext(what));
    version = m.version;
  }
  return Status::Ok();
}

}  // namespace brdf::storage
