// The database schema and its migrations. The full description is in storage/schema.md; in short
// (schema version 6):
//
//   sessions  id, name, plan_kind, plan_json (the plan as submitted), state, state_reason,
//             created_at, started_at, finished_at, created_by_role, total_steps, done_steps
//             (steps done or skipped), white_reflectance, meter_serial, config_json, uuid (v2:
//             global identity, unique), rig (v2: the recording rig's name), state_changed_at
//             (v4: when brdfd last changed state or state_reason)
//   steps     (session_id, step_index) primary key; kind (move|prompt|reference|dark|sample),
//             alpha beta gamma delta (degrees), prompt, prompt_kind, expected_action,
//             target_theta_i target_phi_i target_theta_o target_phi_o (all or none), label,
//             state (pending|done|skipped), note (why skipped), completed_at
//   readings  id; (session_id, step_index) UNIQUE and a foreign key to steps — the database itself
//             refuses a second reading for a step; kind (sample|reference|dark); the pose reached;
//             theta_i phi_i theta_o phi_o; wl_start_nm wl_step_nm wl_count; spectrum (BLOB of
//             wl_count little-endian float64, length checked); quality_code, flagged,
//             integration_ms, attempts, note; reference_reading_id, dark_reading_id (readings of
//             the same session); meter_serial; recorded_at
//   devices   id, session_id (nullable), kind, model, serial, first_seen; unique per
//             (session, kind, model, serial)
//   audit     id, at, role, actor (a token's name, never the token), action, session_id, detail
//   archive_outbox, archive_marks (v3): what the shipper to the lab archive has still to send
//             (triggers note session and step changes while shipping is on; marks for readings,
//             devices, audit; v4: events)
//   session_events (v4)  id, session_id, at, state, reason: one row when a session is created
//             and one per change of its state or reason, written by triggers
//   reading_uncertainty (v5)  reading_id (PK), quantity (brdf|reflectance), bands, value,
//             combined, independent (BLOBs of float64 per band), components (text lines
//             "name sharing id"), contributions (BLOB), not_estimated: a sample reading's
//             uncertainty budget, written with the reading; no row: not estimated
//             (uncertainty_columns.h)
//   adaptive_rounds (v6)  (session_id, round) primary key; first_step, step_count, picks (text
//             lines "alpha beta gamma delta gain"), predicted_gain, uncertainty_left,
//             readings_used, created_at: a round of an adaptive session, stored with its steps
//
// Timestamps are Unix seconds (REAL, UTC). Angles are degrees. Enumerations are lower-case words
// guarded by CHECK constraints.
//
// Versioning: PRAGMA user_version holds the schema version and PRAGMA application_id marks the
// file as brdfd's. Migrations run in order, each in its own transaction together with the
// user_version bump, so a crash mid-migration leaves the previous version intact. A file whose
// version is newer than this build knows is refused, never touched.
#pragma once

#include <cstdint>
#include <span>
#include <string_view>

#include "core/status.h"
#include "storage/sqlite.h"

namespace brdf::storage {

// "BRDF" in ASCII: PRAGMA application_id of every database brdfd creates.
inline constexpr std::int64_t kApplicationId = 0x42524446;

struct Migration {
  int version;                   // the user_version once this migration has run: 1, 2, 3, …
  std::string_view description;  // for messages ("create sessions, steps, readings, …")
  std::string_view sql;          // one or more statements
};

// brdfd's migrations, oldest first. Append only: a released migration never changes.
std::span<const Migration> SchemaMigrations();
// The version a database has after all of SchemaMigrations().
int LatestSchemaVersion();

// Brings `db` up to the last version of `migrations` (which must be numbered 1, 2, 3, …).
// kFailedPrecondition, touching nothing, when the file is newer than `migrations` know or is not a
// brdfd database (another application_id, or tables without a schema version).
Status Migrate(Database& db, std::span<const Migration> migrations = SchemaMigrations());

// The schema version recorded in `db` (0 for a new, empty file).
Result<int> SchemaVersion(Database& db);

}  // namespace brdf::storage
