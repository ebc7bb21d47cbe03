// Checks the daemon tests make on the SQLite file itself, independently of brdfd: plain SQL
// through sqlite3's C API (read-only), plus storage's own CheckSession.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include "core/status.h"

namespace brdf::testing {

// What the database says about one session, counted with SQL.
struct DbSessionCounts {
  std::string state;
  std::string state_reason;
  int total_steps = 0;
  int done_steps_recorded = 0;  // sessions.done_steps
  int steps = 0;                // rows in steps
  int steps_done = 0;
  int steps_pending = 0;
  int measuring_steps_done = 0;  // reference, dark, sample steps done
  int readings = 0;
  int duplicate_readings = 0;  // readings beyond the first of a step
  int orphan_readings = 0;     // readings on a step that is not done, or of another kind
  int step_index_gaps = 0;     // total_steps − distinct step indexes in [0, total_steps)
};
Result<DbSessionCounts> CountSession(const std::string& database, std::int64_t session);

// storage's SessionStore::CheckSession: the problems it finds ("" when none).
Result<std::string> StorageProblems(const std::string& database, std::int64_t session);

// The audit log's (role, actor, action) rows, and whether any column contains `needle`.
struct AuditRow {
  std::string role;
  std::string actor;
  std::string action;
  std::string detail;
};
Result<std::vector<AuditRow>> AuditRows(const std::string& database);

}  // namespace brdf::testing

namespace brdf::testing {

// The kind word of each step of a session ("move", "prompt", "reference", "dark", "sample"),
// by step index, and each step's state ("pending", "done", "skipped").
struct DbStep {
  std::string kind;
  std::string state;
};
Result<std::vector<DbStep>> SessionSteps(const std::string& database, std::int64_t session);

}  // namespace brdf::testing
