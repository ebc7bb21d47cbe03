// SessionStore::CheckSession: the invariants a session's rows must satisfy, checked from the data
// itself (not from what the store believes it wrote). Used by tests and by the crash campaign to
// prove that no kill, at any moment, leaves a step without its reading or a reading twice.
#include <string>

#include "core/status.h"
#include "storage/session_store.h"

namespace brdf::storage {
namespace {

constexpr std::size_t kMaxListed = 10;

// "steps 3, 4, 9" / "readings 12, 15, … (40 in all)".
std::string ListOf(std::string_view noun, const std::vector<std::int64_t>& ids) {
  std::string s(noun);
  for (std::size_t i = 0; i < ids.size() && i < kMaxListed; ++i) {
    s += (i == 0 ? " " : ", ") + std::to_string(ids[i]);
  }
  if (ids.size() > kMaxListed) s += ", … (" + std::to_string(ids.size()) + " in all)";
  return s;
}

// The first column of every row of `sql` with ?1 bound to `session`.
Result<std::vector<std::int64_t>> Ids(Database& db, std::string_view sql, std::int64_t session) {
  BRDF_ASSIGN_OR_RETURN(Statement st, db.Prepare(sql));
  st.Bind(1, session);
  std::vector<std::int64_t> ids;
  while (true) {
    BRDF_ASSIGN_OR_RETURN(bool row, st.Step());
    if (!row) break;
    ids.push_back(st.Int64(0));
  }
  return ids;
}

// The session's row: its plan's step count and done_steps into the report; returns its state.
Result<std::string> ReadSessionRow(Database& db, std::int64_t session, IntegrityReport& report) {
  BRDF_ASSIGN_OR_RETURN(
      Statement st, db.Prepare("SELECT total_steps, done_steps, state FROM sessions WHERE id = ?"));
  st.Bind(1, session);
  BRDF_ASSIGN_OR_RETURN(bool row, st.Step());
  if (!row) return NotFound("no session " + std::to_string(session) + " in the database");
  report.total_steps = st.Int(0);
  report.done_steps_recorded = st.Int(1);
  return st.Text(2);
}

struct StepIndexRange {
  std::int64_t min = 0;
  std::int64_t max = -1;
};

// The stored steps by state into the report; returns the range of their indexes.
Result<StepIndexRange> CountSteps(Database& db, std::int64_t session, IntegrityReport& report) {
  BRDF_ASSIGN_OR_RETURN(
      Statement st,
      db.Prepare("SELECT count(*), ifnull(min(step_index), 0), ifnull(max(step_index), -1), "
                 "total(state = 'done'), total(state = 'skipped'), total(state = 'pending') "
                 "FROM steps WHERE session_id = ?"));
  st.Bind(1, session);
  BRDF_ASSIGN_OR_RETURN(bool row, st.Step());
  StepIndexRange range;
  if (row) {
    report.steps_present = st.Int(0);
    range.min = st.Int64(1);
    range.max = st.Int64(2);
    report.steps_done = static_cast<int>(st.Double(3));
    report.steps_skipped = static_cast<int>(st.Double(4));
    report.steps_pending = static_cast<int>(st.Double(5));
  }
  return range;
}

// The counts against each other: the plan's steps all stored, numbered 0 … n−1, done_steps
// right, nothing pending in a completed session.
void CheckCounts(const std::string& state, const StepIndexRange& range, IntegrityReport& report) {
  auto& problems = report.problems;
  if (report.steps_present != report.total_steps) {
    problems.push_back("the plan has " + std::to_string(report.total_steps) + " steps but " +
                       std::to_string(report.steps_present) + " are stored");
  }
  // step_index is unique per session (primary key); 0 … n−1 then means every step exactly once.
  if (report.steps_present > 0 && (range.min != 0 || range.max != report.steps_present - 1)) {
    problems.push_back("steps are numbered " + std::to_string(range.min) + " to " +
                       std::to_string(range.max) + " instead of 0 to " +
                       std::to_string(report.steps_present - 1));
  }
  if (report.steps_done + report.steps_skipped != report.done_steps_recorded) {
    problems.push_back("done_steps says " + std::to_string(report.done_steps_recorded) + " but " +
                       std::to_string(report.steps_done) + " steps are done and " +
                       std::to_string(report.steps_skipped) + " skipped");
  }
  if (state == "completed" && report.steps_pending > 0) {
    problems.push_back("the session is completed but " + std::to_string(report.steps_pending) +
                       " steps are pending");
  }
}

// A query for the rows that break a rule (?1: the session), and how to name them.
struct RowCheck {
  std::string_view sql;
  std::string_view noun;
  std::string_view problem;
};
constexpr RowCheck kRowChecks[] = {
    {"SELECT r.id FROM readings r LEFT JOIN steps s "
     "ON s.session_id = r.session_id AND s.step_index = r.step_index "
     "WHERE r.session_id = ?1 AND s.step_index IS NULL ORDER BY r.id",
     "readings", "have no step"},
    {"SELECT r.id FROM readings r JOIN steps s "
     "ON s.session_id = r.session_id AND s.step_index = r.step_index "
     "WHERE r.session_id = ?1 AND s.state <> 'done' ORDER BY r.id",
     "readings", "belong to steps that are not done"},
    {"SELECT r.id FROM readings r JOIN steps s "
     "ON s.session_id = r.session_id AND s.step_index = r.step_index "
     "WHERE r.session_id = ?1 AND s.kind <> r.kind ORDER BY r.id",
     "readings", "are of another kind than their step"},
    {"SELECT step_index FROM readings WHERE session_id = ?1 "
     "GROUP BY step_index HAVING count(*) > 1 ORDER BY step_index",
     "steps", "have more than one reading"},
    {"SELECT s.step_index FROM steps s LEFT JOIN readings r "
     "ON r.session_id = s.session_id AND r.step_index = s.step_index "
     "WHERE s.session_id = ?1 AND s.state = 'done' AND s.kind IN ('reference', 'dark', 'sample') "
     "AND r.id IS NULL ORDER BY s.step_index",
     "steps", "are done but have no reading"},
    {"SELECT r.id FROM readings r LEFT JOIN readings ref ON ref.id = r.reference_reading_id "
     "WHERE r.session_id = ?1 AND r.reference_reading_id IS NOT NULL AND (ref.id IS NULL OR "
     "ref.session_id <> r.session_id OR ref.kind <> 'reference') ORDER BY r.id",
     "readings", "name a reference that is not a reference reading of this session"},
    {"SELECT r.id FROM readings r LEFT JOIN readings d ON d.id = r.dark_reading_id "
     "WHERE r.session_id = ?1 AND r.dark_reading_id IS NOT NULL AND (d.id IS NULL OR "
     "d.session_id <> r.session_id OR d.kind <> 'dark') ORDER BY r.id",
     "readings", "name a dark reading that is not a dark reading of this session"},
    {"SELECT id FROM readings WHERE session_id = ?1 AND "
     "(typeof(spectrum) <> 'blob' OR length(spectrum) <> 8 * wl_count) ORDER BY id",
     "readings", "have a spectrum whose size does not match their wavelength grid"},
};

// PRAGMA integrity_check's answer into the report (a problem unless "ok").
Status CheckIntegrity(Database& db, IntegrityReport& report) {
  BRDF_ASSIGN_OR_RETURN(Statement st, db.Prepare("PRAGMA integrity_check"));
  while (true) {
    BRDF_ASSIGN_OR_RETURN(bool row, st.Step());
    if (!row) break;
    if (!report.integrity_check.empty()) report.integrity_check += "; ";
    report.integrity_check += st.Text(0);
  }
  if (report.integrity_check != "ok") {
    report.problems.push_back("PRAGMA integrity_check reports: " + report.integrity_check);
  }
  return Status::Ok();
}

// PRAGMA foreign_key_check: how many references are broken, and the first.
Status CheckForeignKeys(Database& db, std::vector<std::string>& problems) {
  BRDF_ASSIGN_OR_RETURN(Statement st, db.Prepare("PRAGMA foreign_key_check"));
  int broken = 0;
  std::string first;
  while (true) {
    BRDF_ASSIGN_OR_RETURN(bool row, st.Step());
    if (!row) break;
    if (broken++ == 0) {
      first = st.Text(0) + " row " + std::to_string(st.Int64(1)) + " refers to a missing " +
              st.Text(2) + " row";
    }
  }
  if (broken > 0) {
    problems.push_back("PRAGMA foreign_key_check finds " + std::to_string(broken) +
                       " broken references (first: " + first + ")");
  }
  return Status::Ok();
}

}  // namespace

std::string IntegrityReport::Summary() const {
  if (problems.empty()) return "session " + std::to_string(session_id) + ": ok";
  std::string s = "session " + std::to_string(session_id) + ": ";
  for (std::size_t i = 0; i < problems.size(); ++i) s += (i == 0 ? "" : "; ") + problems[i];
  return s;
}

Result<IntegrityReport> SessionStore::CheckSession(std::int64_t session) {
  BRDF_ASSIGN_OR_RETURN(ReaderPool::Lease lease, readers_->Acquire());
  Database& db = *lease;
  // One snapshot for every query: a writer committing meanwhile cannot make counts disagree.
  BRDF_ASSIGN_OR_RETURN(Transaction tx, Transaction::BeginRead(db));

  IntegrityReport report;
  report.session_id = session;
  BRDF_ASSIGN_OR_RETURN(const std::string state, ReadSessionRow(db, session, report));
  BRDF_ASSIGN_OR_RETURN(const StepIndexRange range, CountSteps(db, session, report));
  BRDF_ASSIGN_OR_RETURN(
      std::int64_t readings,
      db.QueryInt64("SELECT count(*) FROM readings WHERE session_id = " + std::to_string(session)));
  report.readings = static_cast<int>(readings);

  CheckCounts(state, range, report);
  for (const RowCheck& check : kRowChecks) {
    BRDF_ASSIGN_OR_RETURN(std::vector<std::int64_t> ids, Ids(db, check.sql, session));
    if (!ids.empty()) {
      report.problems.push_back(ListOf(check.noun, ids) + " " + std::string(check.problem));
    }
  }
  // The file as a whole: b-trees, indexes and every foreign key.
  BRDF_RETURN_IF_ERROR(CheckIntegrity(db, report));
  BRDF_RETURN_IF_ERROR(CheckForeignKeys(db, report.problems));
  return report;
}

}  // namespace brdf::storage
