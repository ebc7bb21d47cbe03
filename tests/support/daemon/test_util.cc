#include "tests/support/daemon/test_util.h"

#include <sqlite3.h>

#include <memory>

#include "storage/session_store.h"

namespace brdf::testing {
namespace {

struct DbCloser {
  void operator()(sqlite3* db) const { sqlite3_close(db); }
};
using Db = std::unique_ptr<sqlite3, DbCloser>;

Result<Db> OpenReadOnly(const std::string& path) {
  sqlite3* raw = nullptr;
  const int rc = sqlite3_open_v2(path.c_str(), &raw, SQLITE_OPEN_READONLY, nullptr);
  Db db(raw);
  if (rc != SQLITE_OK) {
    return IoError("cannot open " + path + ": " + (raw ? sqlite3_errmsg(raw) : "out of memory"));
  }
  sqlite3_busy_timeout(raw, 5000);
  return db;
}

// Runs `sql` with `session` bound to ?1; calls `row` per result row.
template <typename Fn>
Status Query(sqlite3* db, const std::string& sql, std::int64_t session, Fn row) {
  sqlite3_stmt* stmt = nullptr;
  if (sqlite3_prepare_v2(db, sql.c_str(), -1, &stmt, nullptr) != SQLITE_OK) {
    return Internal("prepare \"" + sql + "\": " + sqlite3_errmsg(db));
  }
  if (sql.find("?1") != std::string::npos) sqlite3_bind_int64(stmt, 1, session);
  int rc = SQLITE_OK;
  while ((rc = sqlite3_step(stmt)) == SQLITE_ROW) row(stmt);
  sqlite3_finalize(stmt);
  if (rc != SQLITE_DONE) return Internal("step \"" + sql + "\": " + sqlite3_errmsg(db));
  return Status::Ok();
}

Status Int(sqlite3* db, const std::string& sql, std::int64_t session, int* out) {
  return Query(db, sql, session, [out](sqlite3_stmt* s) { *out = sqlite3_column_int(s, 0); });
}

std::string Text(sqlite3_stmt* s, int column) {
  const unsigned char* t = sqlite3_column_text(s, column);
  return t ? reinterpret_cast<const char*>(t) : "";
}

}  // namespace

Result<DbSessionCounts> CountSession(const std::string& database, std::int64_t session) {
  BRDF_ASSIGN_OR_RETURN(Db db, OpenReadOnly(database));
  sqlite3* d = db.get();
  DbSessionCounts c;
  BRDF_RETURN_IF_ERROR(Query(d,
                             "SELECT state, state_reason, total_steps, done_steps FROM sessions "
                             "WHERE id = ?1",
                             session, [&c](sqlite3_stmt* s) {
                               c.state = Text(s, 0);
                               c.state_reason = Text(s, 1);
                               c.total_steps = sqlite3_column_int(s, 2);
                               c.done_steps_recorded = sqlite3_column_int(s, 3);
                             }));
  BRDF_RETURN_IF_ERROR(
      Int(d, "SELECT COUNT(*) FROM steps WHERE session_id = ?1", session, &c.steps));
  BRDF_RETURN_IF_ERROR(Int(d, "SELECT COUNT(*) FROM steps WHERE session_id = ?1 AND state = 'done'",
                           session, &c.steps_done));
  BRDF_RETURN_IF_ERROR(Int(d,
                           "SELECT COUNT(*) FROM steps WHERE session_id = ?1 AND state = "
                           "'pending'",
                           session, &c.steps_pending));
  BRDF_RETURN_IF_ERROR(Int(d,
                           "SELECT COUNT(*) FROM steps WHERE session_id = ?1 AND state = 'done' "
                           "AND kind IN ('reference', 'dark', 'sample')",
                           session, &c.measuring_steps_done));
  BRDF_RETURN_IF_ERROR(
      Int(d, "SELECT COUNT(*) FROM readings WHERE session_id = ?1", session, &c.readings));
  BRDF_RETURN_IF_ERROR(Int(d,
                           "SELECT COALESCE(SUM(n - 1), 0) FROM (SELECT COUNT(*) AS n FROM "
                           "readings WHERE session_id = ?1 GROUP BY step_index)",
                           session, &c.duplicate_readings));
  BRDF_RETURN_IF_ERROR(Int(d,
                           "SELECT COUNT(*) FROM readings r LEFT JOIN steps s ON s.session_id = "
                           "r.session_id AND s.step_index = r.step_index WHERE r.session_id = ?1 "
                           "AND (s.state IS NULL OR s.state != 'done' OR s.kind != r.kind)",
                           session, &c.orphan_readings));
  int distinct = 0;
  BRDF_RETURN_IF_ERROR(Int(d,
                           "SELECT COUNT(DISTINCT s.step_index) FROM steps s JOIN sessions x ON "
                           "x.id = s.session_id WHERE s.session_id = ?1 AND s.step_index >= 0 AND "
                           "s.step_index < x.total_steps",
                           session, &distinct));
  c.step_index_gaps = c.total_steps - distinct;
  return c;
}

Result<std::string> StorageProblems(const std::string& database, std::int64_t session) {
  BRDF_ASSIGN_OR_RETURN(std::unique_ptr<storage::SessionStore> store,
                        storage::SessionStore::Open(database));
  BRDF_ASSIGN_OR_RETURN(storage::IntegrityReport report, store->CheckSession(session));
  return report.ok() ? std::string() : report.Summary();
}

Result<std::vector<AuditRow>> AuditRows(const std::string& database) {
  BRDF_ASSIGN_OR_RETURN(Db db, OpenReadOnly(database));
  std::vector<AuditRow> rows;
  BRDF_RETURN_IF_ERROR(
      Query(db.get(), "SELECT role, actor, action, detail FROM audit ORDER BY id", 0,
            [&rows](sqlite3_stmt* s) {
              rows.push_back(AuditRow{Text(s, 0), Text(s, 1), Text(s, 2), Text(s, 3)});
            }));
  return rows;
}

}  // namespace brdf::testing

namespace brdf::testing {

Result<std::vector<DbStep>> SessionSteps(const std::string& database, std::int64_t session) {
  BRDF_ASSIGN_OR_RETURN(Db db, OpenReadOnly(database));
  std::vector<DbStep> steps;
  BRDF_RETURN_IF_ERROR(Query(db.get(),
                             "SELECT kind, state FROM steps WHERE session_id = ?1 ORDER BY "
                             "step_index",
                             session, [&steps](sqlite3_stmt* s) {
                               steps.push_back(DbStep{Text(s, 0), Text(s, 1)});
                             }));
  return steps;
}

}  // namespace brdf::testing
