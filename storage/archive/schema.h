// The lab archive's schema on PostgreSQL and its migrations. The full description is in
// storage/archive/schema.md; in short (archive schema version 5):
//
//   archive_schema  version, description, applied_at: one row per migration applied
//   sessions  uuid (primary key: the session's global identity), rig, rig_session_id (the id on
//             its rig; unique per rig), the rig's session columns (name … config_json), and the
//             catalogue taken from the plan's sample block: sample_id, sample_name, material,
//             sample_description, tags (text[]), white_standard_id; archived_at, updated_at;
//             archive_id (v2: the session's id in brdf-archive's API, unique)
//   steps     (session_uuid, step_index) primary key; the rig's step columns
//   readings  (session_uuid, step_index) primary key — one reading per step, as on the rig;
//             rig_reading_id (the reading's id on its rig, unique per session); the rig's reading
//             columns; spectrum bytea (wl_count little-endian float64)
//   devices   (rig, rig_device_id) primary key; session_uuid, kind, model, serial, first_seen
//   audit     (rig, rig_audit_id) primary key; at, role, actor, action, session_uuid, detail
//   session_events (v3)  (session_uuid, rig_event_id) primary key; at, state, reason,
//             archived_at: each session's history of states as its rig recorded it
//   reading_uncertainty (v4)  (session_uuid, step_index) primary key: a sample reading's budget
//   adaptive_rounds (v5)  (session_uuid, round) primary key: an adaptive session's rounds as its
//             rig stored them, with the rig time and prompts spent before each and its cost
//
// Every write is an idempotent upsert keyed by these keys, so a batch shipped twice (a crash
// between the archive's commit and the rig's mark) changes nothing the second time.
#pragma once

#include <span>
#include <string_view>

#include "core/status.h"
#include "storage/archive/pg.h"

namespace brdf::storage {

struct ArchiveMigration {
  int version;  // 1, 2, 3, …
  std::string_view description;
  std::string_view sql;
};

std::span<const ArchiveMigration> ArchiveMigrations();
int LatestArchiveVersion();

// Brings the archive up to the latest version. Serialised across rigs and archive servers by a
// transaction-scoped advisory lock, each migration in its own transaction with its version row.
// kFailedPrecondition, touching nothing, when the archive's version is newer than this build.
Status MigrateArchive(PgConnection& conn,
                      std::span<const ArchiveMigration> migrations = ArchiveMigrations());

// The archive's schema version (0 for an empty database).
Result<int> ArchiveVersion(PgConnection& conn);

}  // namespace brdf::storage
