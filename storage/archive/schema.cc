#include "storage/archive/schema.h"

#include <array>
#include <string>

namespace brdf::storage {
namespace {

// Version 1. Kept verbatim once released; later changes are new migrations.
constexpr std::string_view kArchiveV1 = R"sql(
CREATE TABLE sessions (
  uuid               uuid PRIMARY KEY,
  rig                text NOT NULL,
  rig_session_id     bigint NOT NULL,
  name               text NOT NULL,
  plan_kind          text NOT NULL,
  plan_json          text NOT NULL,
  state              text NOT NULL CHECK (state IN ('queued', 'running', 'pausing', 'paused',
                       'awaiting_operator', 'completed', 'aborted', 'failed')),
  state_reason       text NOT NULL DEFAULT '',
  created_at         double precision NOT NULL,
  started_at         double precision,
  finished_at        double precision,
  created_by_role    text NOT NULL DEFAULT '',
  total_steps        integer NOT NULL CHECK (total_steps >= 0),
  done_steps         integer NOT NULL CHECK (done_steps >= 0 AND done_steps <= total_steps),
  white_reflectance  double precision,
  meter_serial       text NOT NULL DEFAULT '',
  config_json        text NOT NULL DEFAULT '{}',
  sample_id          text NOT NULL DEFAULT '',
  sample_name        text NOT NULL DEFAULT '',
  material           text NOT NULL DEFAULT '',
  sample_description text NOT NULL DEFAULT '',
  tags               text[] NOT NULL DEFAULT '{}',
  white_standard_id  text NOT NULL DEFAULT '',
  archived_at        timestamptz NOT NULL DEFAULT now(),
  updated_at         timestamptz NOT NULL DEFAULT now(),
  UNIQUE (rig, rig_session_id)
);
CREATE INDEX sessions_by_created ON sessions (created_at DESC, uuid);
CREATE INDEX sessions_by_rig ON sessions (rig, created_at DESC);
CREATE INDEX sessions_by_sample_id ON sessions (sample_id);
CREATE INDEX sessions_by_sample_name ON sessions (lower(sample_name));
CREATE INDEX sessions_by_material ON sessions (lower(material));
CREATE INDEX sessions_by_state ON sessions (state);
CREATE INDEX sessions_by_tag ON sessions USING gin (tags);

CREATE TABLE steps (
  session_uuid    uuid NOT NULL REFERENCES sessions (uuid),
  step_index      integer NOT NULL CHECK (step_index >= 0),
  kind            text NOT NULL CHECK (kind IN ('move', 'prompt', 'reference', 'dark', 'sample')),
  alpha           double precision NOT NULL,
  beta            double precision NOT NULL,
  gamma           double precision NOT NULL,
  delta           double precision NOT NULL,
  prompt          text,
  prompt_kind     text,
  expected_action text,
  target_theta_i  double precision,
  target_phi_i    double precision,
  target_theta_o  double precision,
  target_phi_o    double precision,
  label           text NOT NULL DEFAULT '',
  state           text NOT NULL CHECK (state IN ('pending', 'done', 'skipped')),
  note            text,
  completed_at    double precision,
  PRIMARY KEY (session_uuid, step_index)
);

CREATE TABLE readings (
  session_uuid         uuid NOT NULL,
  step_index           integer NOT NULL,
  rig_reading_id       bigint NOT NULL,
  kind                 text NOT NULL CHECK (kind IN ('sample', 'reference', 'dark')),
  alpha                double precision NOT NULL,
  beta                 double precision NOT NULL,
  gamma                double precision NOT NULL,
  delta                double precision NOT NULL,
  theta_i              double precision NOT NULL,
  phi_i                double precision NOT NULL,
  theta_o              double precision NOT NULL,
  phi_o                double precision NOT NULL,
  wl_start_nm          double precision NOT NULL,
  wl_step_nm           double precision NOT NULL CHECK (wl_step_nm > 0),
  wl_count             integer NOT NULL CHECK (wl_count > 0),
  spectrum             bytea NOT NULL CHECK (length(spectrum) = 8 * wl_count),
  quality_code         integer NOT NULL DEFAULT 0,
  flagged              boolean NOT NULL DEFAULT false,
  integration_ms       integer NOT NULL DEFAULT 0,
  attempts             integer NOT NULL DEFAULT 1,
  note                 text NOT NULL DEFAULT '',
  reference_reading_id bigint,
  dark_reading_id      bigint,
  meter_serial         text NOT NULL DEFAULT '',
  recorded_at          double precision NOT NULL,
  archived_at          timestamptz NOT NULL DEFAULT now(),
  PRIMARY KEY (session_uuid, step_index),
  UNIQUE (session_uuid, rig_reading_id),
  FOREIGN KEY (session_uuid, step_index) REFERENCES steps (session_uuid, step_index)
);

CREATE TABLE devices (
  rig           text NOT NULL,
  rig_device_id bigint NOT NULL,
  session_uuid  uuid REFERENCES sessions (uuid),
  kind          text NOT NULL,
  model         text NOT NULL,
  serial        text NOT NULL,
  first_seen    double precision NOT NULL,
  PRIMARY KEY (rig, rig_device_id)
);

CREATE TABLE audit (
  rig          text NOT NULL,
  rig_audit_id bigint NOT NULL,
  at           double precision NOT NULL,
  role         text NOT NULL,
  actor        text NOT NULL,
  action       text NOT NULL,
  session_uuid uuid REFERENCES sessions (uuid),
  detail       text NOT NULL DEFAULT '',
  PRIMARY KEY (rig, rig_audit_id)
);
CREATE INDEX audit_by_session ON audit (session_uuid) WHERE session_uuid IS NOT NULL;
)sql";

// Version 2: brdf-archive's session ids. The API names a session by a positive number; across
// rigs the rigs' own ids collide, so the archive numbers its sessions itself (existing rows are
// numbered by the ALTER, in no particular order; new ones as they are first shipped).
constexpr std::string_view kArchiveV2 = R"sql(
ALTER TABLE sessions ADD COLUMN archive_id bigserial;
CREATE UNIQUE INDEX sessions_by_archive_id ON sessions (archive_id);
)sql";

// Version 3: each session's history of states, as the rig recorded it (its schema v4), keyed by
// the session's global id and the event's id on the rig.
constexpr std::string_view kArchiveV3 = R"sql(
CREATE TABLE session_events (
  session_uuid uuid NOT NULL REFERENCES sessions (uuid),
  rig_event_id bigint NOT NULL,
  at           double precision NOT NULL,
  state        text NOT NULL CHECK (state IN ('queued', 'running', 'pausing', 'paused',
                 'awaiting_operator', 'completed', 'aborted', 'failed')),
  reason       text NOT NULL DEFAULT '',
  archived_at  timestamptz NOT NULL DEFAULT now(),
  PRIMARY KEY (session_uuid, rig_event_id)
);
)sql";

// Version 4: each sample reading's uncertainty budget, as the rig stores it (its schema v5;
// docs/uncertainty.md), keyed like the reading. A reading without a row is "not estimated" --
// every reading shipped before, darks and references.
constexpr std::string_view kArchiveV4 = R"sql(
CREATE TABLE reading_uncertainty (
  session_uuid  uuid    NOT NULL,
  step_index    integer NOT NULL,
  quantity      text    NOT NULL CHECK (quantity IN ('brdf', 'reflectance')),
  bands         integer NOT NULL CHECK (bands > 0),
  value         bytea   NOT NULL CHECK (length(value) = 8 * bands),
  combined      bytea   NOT NULL CHECK (length(combined) = 8 * bands),
  independent   bytea   NOT NULL CHECK (length(independent) = 8 * bands),
  components    text    NOT NULL,
  contributions bytea   NOT NULL CHECK (length(contributions) % (8 * bands) = 0),
  not_estimated text    NOT NULL DEFAULT '',
  archived_at   timestamptz NOT NULL DEFAULT now(),
  PRIMARY KEY (session_uuid, step_index),
  FOREIGN KEY (session_uuid, step_index) REFERENCES readings (session_uuid, step_index)
);
)sql";

// Version 5: the rounds of adaptive sessions, as their rig stores them (its schema v6;
// docs/adaptive.md) with what each meant for the budget by the rig's timing model (the rig time
// and prompts spent before it, its own steps' cost), which ListAdaptiveRounds answers and only the
// rig can compute (it needs the rig's description). Keyed (session_uuid, round); rounds never
// change on the rig, so a row is written once.
constexpr std::string_view kArchiveV5 = R"sql(
CREATE TABLE adaptive_rounds (
  session_uuid     uuid    NOT NULL REFERENCES sessions (uuid),
  round            integer NOT NULL CHECK (round >= 1),
  first_step       integer NOT NULL CHECK (first_step >= 0),
  step_count       integer NOT NULL CHECK (step_count >= 1),
  picks            text    NOT NULL,
  predicted_gain   double precision NOT NULL,
  uncertainty_left double precision NOT NULL,
  readings_used    integer NOT NULL CHECK (readings_used >= 0),
  created_at       double precision NOT NULL,
  spent_rig_s      double precision NOT NULL,
  spent_prompts    integer NOT NULL CHECK (spent_prompts >= 0),
  rig_s            double precision NOT NULL,
  prompts          integer NOT NULL CHECK (prompts >= 0),
  archived_at      timestamptz NOT NULL DEFAULT now(),
  PRIMARY KEY (session_uuid, round)
);
)sql";

constexpr std::array<ArchiveMigration, 5> kArchiveMigrations{{
    {1, "create sessions, steps, readings, devices and audit", kArchiveV1},
    {2, "number the sessions for brdf-archive (sessions.archive_id)", kArchiveV2},
    {3, "keep each session's history of states (session_events)", kArchiveV3},
    {4, "keep each reading's uncertainty budget (reading_uncertainty)", kArchiveV4},
    {5, "keep the rounds of adaptive sessions (adaptive_rounds)", kArchiveV5},
}};

// "BRDF": the advisory lock key that serialises migrations across rigs and servers.
constexpr std::string_view kMigrationLock = "SELECT pg_advisory_xact_lock(1112687686)";

}  // namespace

std::span<const ArchiveMigration> ArchiveMigrations() {
  return kArchiveMigrations;
}

int LatestArchiveVersion() {
  return kArchiveMigrations.back().version;
}

Result<int> ArchiveVersion(PgConnection& conn) {
  BRDF_ASSIGN_OR_RETURN(PgResult exists,
                        conn.Query("SELECT to_regclass('archive_schema') IS NOT NULL"));
  if (exists.Text(0, 0) != "t") return 0;
  BRDF_ASSIGN_OR_RETURN(PgResult v,
                        conn.Query("SELECT coalesce(max(version), 0) FROM archive_schema"));
  return static_cast<int>(v.Int64(0, 0));
}

namespace {

Status NewerThanThisBuild(int version, int latest) {
  return FailedPrecondition("the archive has schema version " + std::to_string(version) +
                            ", newer than the latest this build knows (" + std::to_string(latest) +
                            "): it was written by a newer brdfd; upgrade this rig or archive "
                            "server");
}

// One migration in its transaction, under the lock that serialises migrations: applied unless
// another rig or server applied it since `before` was read.
Status ApplyMigration(PgConnection& conn, const ArchiveMigration& m, int latest) {
  const std::string what = "migrating the archive to schema version " + std::to_string(m.version) +
                           " (" + std::string(m.description) + ")";
  Result<PgTransaction> tx = PgTransaction::Begin(conn);
  if (!tx.ok()) return tx.status().WithContext(what);
  BRDF_RETURN_IF_ERROR(conn.Exec(kMigrationLock).WithContext(what));
  BRDF_RETURN_IF_ERROR(
      conn.Exec("CREATE TABLE IF NOT EXISTS archive_schema (version integer PRIMARY KEY, "
                "description text NOT NULL, applied_at timestamptz NOT NULL DEFAULT now())")
          .WithContext(what));
  Result<int> now = ArchiveVersion(conn);
  if (!now.ok()) return now.status().WithContext(what);
  if (*now > latest) return NewerThanThisBuild(*now, latest);
  if (*now >= m.version) return Status::Ok();  // the destructor rolls the empty transaction back
  BRDF_RETURN_IF_ERROR(conn.Exec(m.sql).WithContext(what));
  Result<PgResult> row =
      conn.Query("INSERT INTO archive_schema (version, description) VALUES ($1, $2)",
                 PgParams().Add(m.version).Add(m.description));
  if (!row.ok()) return row.status().WithContext(what);
  return tx->Commit().WithContext(what);
}

}  // namespace

Status MigrateArchive(PgConnection& conn, std::span<const ArchiveMigration> migrations) {
  const int latest = static_cast<int>(migrations.size());
  // Read first, without a lock: an archive already at this build's version (every reconnect of
  // every rig) needs no transaction, and a failure here is a failed check, not a migration.
  Result<int> before = ArchiveVersion(conn);
  if (!before.ok()) return before.status().WithContext("checking the archive's schema version");
  if (*before > latest) return NewerThanThisBuild(*before, latest);
  for (const ArchiveMigration& m : migrations) {
    if (*before >= m.version) continue;
    BRDF_RETURN_IF_ERROR(ApplyMigration(conn, m, latest));
  }
  return Status::Ok();
}

}  // namespace brdf::storage
