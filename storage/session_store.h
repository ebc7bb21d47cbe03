// SessionStore: the daemon's durable record of measurement sessions. Everything a session needs to
// survive a crash, a power cut or a restart lives here, in one SQLite file (schema.h, schema.md).
//
// Guarantees the daemon can build on:
//   - A session and all its planned steps are created in one transaction: a session never exists
//     without its plan.
//   - A step's reading and the step's done mark (and the session's done_steps) commit together
//     (CompleteStepWithReading): after any crash, the database holds either both or neither. A
//     step that is already done is refused, and the database itself forbids a second reading for
//     a step, so a retried call never duplicates a reading.
//   - Committed means durable: WAL journal with synchronous=FULL (fsync on every commit).
//   - Resuming: RecoverInterruptedSessions() at start-up parks sessions a dead daemon was driving
//     as paused; FirstUnfinishedStep() says where each resumes.
//
// Threading: all methods are thread-safe. Writes go through one connection under a mutex. Reads
// use a small pool of separate connections, so a reader (a client streaming readings, a status
// query) never waits behind a writer's fsync and never blocks it (WAL snapshot isolation).
//
// Process: open one SessionStore per process; after fork(), open a new one in the child.
#pragma once

#include <chrono>
#include <cstdint>
#include <functional>
#include <memory>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "core/mutex.h"
#include "core/status.h"
#include "storage/reader_pool.h"
#include "storage/records.h"
#include "storage/session_reader.h"
#include "storage/ship_batch.h"
#include "storage/sqlite.h"

namespace brdf::storage {

// The reason RecoverInterruptedSessions gives the sessions it pauses.
inline constexpr std::string_view kRecoveredReason =
    "recovered after a restart: the daemon stopped without a clean shutdown while this session "
    "ran; paused at its first unfinished step (resume it to go on)";

// What CheckSession found. ok() when `problems` is empty.
struct IntegrityReport {
  std::int64_t session_id = 0;
  int total_steps = 0;    // as recorded in the session
  int steps_present = 0;  // rows in steps
  int steps_done = 0;
  int steps_skipped = 0;
  int steps_pending = 0;
  int done_steps_recorded = 0;  // sessions.done_steps
  int readings = 0;
  std::string integrity_check;        // PRAGMA integrity_check's answer ("ok" when sound)
  std::vector<std::string> problems;  // one sentence each, naming the step or reading

  bool ok() const { return problems.empty(); }
  // All problems on one line, for a Status or a log.
  std::string Summary() const;
};

class SessionStore final : public SessionReader {
 public:
  struct Options {
    // How long a write waits for another process's lock (e.g. a backup) before kTimeout.
    std::chrono::milliseconds busy_timeout{5000};
    // Optional cap on the database size (bytes, 0 = none). Writes past it fail like a full disk.
    std::int64_t max_database_bytes = 0;
    // Wall clock for timestamps (Unix seconds). Default: the system clock.
    std::function<UnixSeconds()> wall_clock;
  };

  // Opens (creating if needed) and migrates the database at `path`. kIoError when the file or its
  // directory cannot be written; kFailedPrecondition when the file is from a newer brdfd or not a
  // brdfd database.
  static Result<std::unique_ptr<SessionStore>> Open(const std::string& path, Options options);
  static Result<std::unique_ptr<SessionStore>> Open(const std::string& path) {
    return Open(path, Options());
  }
  ~SessionStore() override;

  const std::string& path() const { return path_; }

  // --- Sessions ---------------------------------------------------------------------------------

  // Creates a queued session with all its steps, numbered 0, 1, 2, … in order, in ONE transaction.
  // kInvalidArgument when the steps are empty or misnumbered.
  Result<std::int64_t> CreateSession(const NewSession& session,
                                     const std::vector<StepRecord>& steps);

  // Appends a round of an adaptive session: its steps (numbered total_steps, total_steps + 1, …,
  // as round.first_step says), the session's total_steps raised by their number, and the round's
  // record (adaptive_rounds), in ONE transaction: a crash leaves the whole round or none of it.
  //   kNotFound            no such session;
  //   kFailedPrecondition  the session has ended, or round.round is not the next round number
  //                        (a round chosen twice is refused, nothing is written), or
  //                        round.first_step is not the session's total_steps;
  //   kInvalidArgument     no steps, misnumbered steps, a non-finite angle.
  Status AppendRound(const RoundRecord& round, const std::vector<StepRecord>& steps);
  // The session's rounds, in order (empty for a session that has none).
  Result<std::vector<RoundRecord>> GetRounds(std::int64_t session);

  // Moves a session to `state`, recording why. Sets started_at the first time it becomes running
  // and finished_at when it becomes completed, aborted or failed. kFailedPrecondition when the
  // session is already in a terminal state, or when it is to be completed with steps pending.
  Status SetSessionState(std::int64_t session, SessionState state, std::string reason);

  // The meter actually in use, once identified (sessions.meter_serial).
  Status SetSessionMeterSerial(std::int64_t session, const std::string& meter_serial);

  Result<SessionRecord> GetSession(std::int64_t session) override;
  // The session with this global id; kNotFound when there is none.
  Result<SessionRecord> GetSessionByUuid(const std::string& uuid);
  // Sessions recorded before rigs had names (rig '') become `rig`'s: the daemon calls it at start
  // with its own name, since a database belongs to one rig.
  Status AdoptUnnamedSessions(const std::string& rig);
  // All sessions, oldest first.
  Result<std::vector<SessionRecord>> ListSessions();

  // At daemon start: sessions left running, pausing or awaiting_operator (their daemon died)
  // become paused with reason kRecoveredReason. Returns their ids, ascending.
  Result<std::vector<std::int64_t>> RecoverInterruptedSessions();

  // --- Steps ------------------------------------------------------------------------------------

  Result<std::vector<StepRecord>> GetSteps(std::int64_t session) override;
  // The session's history of states (schema v4's session_events), oldest first.
  Result<std::vector<SessionEventRecord>> ListSessionEvents(std::int64_t session) override;
  // The lowest-numbered pending step; nullopt when every step is done or skipped.
  Result<std::optional<int>> FirstUnfinishedStep(std::int64_t session);

  // Stores the reading of a measuring step (reference, dark, sample), marks the step done and
  // counts it in done_steps, all in ONE transaction. The reading's id, session_id and step_index
  // are taken from the arguments; recorded_at from the clock when 0. Returns the reading's id.
  //   kNotFound            no such session or step;
  //   kFailedPrecondition  the step is not pending (already done: nothing is written, so a retried
  //                        call is harmless), or the session is queued or finished;
  //   kInvalidArgument     the step takes no reading (move, prompt), the reading's kind does not
  //                        match the step, the spectrum does not match its grid, or the reference/
  //                        dark reading named is not one of this session's of that kind;
  //   kFailedPrecondition  the reading's wavelength grid is not the session's (its first
  //                        reading's): a session keeps one grid;
  //   kIoError             the disk refused the write (nothing of it was kept).
  Result<std::int64_t> CompleteStepWithReading(std::int64_t session, int step_index,
                                               const ReadingRecord& reading);

  // Replaces the uncertainty budgets of sample readings of `session` (reading id, budget), all in
  // ONE transaction: the budgets a finished session estimates again with what only the whole
  // session knows (docs/uncertainty.md). After any crash the database holds either every new
  // budget or every old one.
  //   kNotFound            no such session, or a reading id that is not one of its readings;
  //   kInvalidArgument     a reading that is not a sample, or a budget that does not fit its
  //                        reading's grid (nothing is written);
  //   kIoError             the disk refused the write (nothing of it was kept).
  Status ReplaceReadingUncertainties(
      std::int64_t session,
      const std::vector<std::pair<std::int64_t, uncertainty::ReadingBudget>>& budgets);

  // Marks a move or prompt step done (measuring steps complete with their reading or are skipped).
  Status CompleteStep(std::int64_t session, int step_index);

  // Marks a pending step skipped (an unreachable pose, the operator's decision), with why.
  Status SkipStep(std::int64_t session, int step_index, std::string note);

  // --- Readings ---------------------------------------------------------------------------------

  // Up to `limit` (> 0) readings of `session` with id > after_id, ascending id: page with the last
  // id seen. Readings are append-only, so paging never skips or repeats one.
  Result<std::vector<ReadingRecord>> GetReadings(std::int64_t session, std::int64_t after_id,
                                                 int limit) override;
  // The same pages as GetReadings without the spectra (SessionReader).
  Result<std::vector<ReadingPointRecord>> GetReadingPoints(std::int64_t session,
                                                           std::int64_t after_id,
                                                           int limit) override;
  Result<ReadingRecord> GetReading(std::int64_t reading_id);
  // Calls `visit` for every reading of `session` in id order, a page at a time (memory bounded by
  // one page; no lock or read transaction is held while `visit` runs, so it may be slow). A
  // non-OK Status from `visit` stops the walk and is returned.
  Status ForEachReading(std::int64_t session,
                        const std::function<Status(const ReadingRecord&)>& visit);
  // Number of readings stored for `session`.
  Result<int> CountReadings(std::int64_t session);

  // --- Devices and audit ------------------------------------------------------------------------

  // Records a device once per (session, kind, model, serial); later calls keep first_seen.
  Status RecordDevice(const DeviceRecord& device);
  Result<std::vector<DeviceRecord>> GetDevices(std::optional<std::int64_t> session);
  Result<std::vector<DeviceRecord>> GetSessionDevices(std::int64_t session) override {
    return GetDevices(session);
  }

  Status AppendAudit(const AuditRecord& entry);
  // The newest `limit` (> 0) entries, newest first; of one session, or of all when nullopt.
  Result<std::vector<AuditRecord>> GetAudit(std::optional<std::int64_t> session, int limit);

  // --- Shipping to the lab archive (session_store_archive.cc, archive-schema.md) -------------

  // Turns the outbox on or off. Turning it on when it was off queues every session (and all its
  // steps) again, since changes made while it was off were not noted; off clears it.
  Status SetArchiveShipping(bool enabled);
  // The next batch: up to `max_changes` outbox entries, and -- only when the outbox is drained in
  // the same snapshot, so that every session and step a row refers to is shipped before it --
  // up to `max_readings` readings, and the devices and audit entries above their marks.
  Result<ShipBatch> NextShipBatch(int max_readings, int max_changes);
  // After the archive committed `batch`: moves the marks and drops the outbox entries it covered,
  // in one transaction.
  Status MarkShipped(const ShipBatch& batch);
  Result<ShipLag> ShippingLag();

  // --- Checking ---------------------------------------------------------------------------------

  // Verifies a session's invariants: every planned step present exactly once (0 … total_steps−1),
  // every reading attached to a done measuring step of the matching kind and every done measuring
  // step with exactly one reading, no reading on a pending or skipped step, done_steps equal to
  // the steps done or skipped, references/darks within the session, spectra the size of their
  // grid; plus PRAGMA integrity_check and foreign_key_check. kNotFound for an unknown session.
  Result<IntegrityReport> CheckSession(std::int64_t session);

 private:
  SessionStore(std::string path, Options options, std::unique_ptr<Database> writer);
  UnixSeconds Now() const;
  Status MarkStepFinished(std::int64_t session, int step_index, StepState state,
                          std::optional<std::string> note, bool measuring_allowed);

  std::string path_;
  Options options_;
  Mutex write_mu_;
  std::unique_ptr<Database> writer_ PT_GUARDED_BY(write_mu_);
  std::unique_ptr<ReaderPool> readers_;
};

}  // namespace brdf::storage
