// ArchiveReader: the lab archive in PostgreSQL (archive-schema.md) read as sessions, for
// brdf-archive. It is a SessionReader (session_reader.h), so the daemon's index cache -- and with
// it Interpolate and InterpolateBatch -- answers from the archive with the same code, over the
// same records, as the rig answers from its SQLite file: bit for bit the same numbers (timestamps,
// angles and spectra are stored exactly, see archive-schema.md's conventions).
//
// Ids: a session is known by its archive_id (schema v2), unique across rigs; its readings keep
// their ids on the rig (rig_reading_id), which references and darks name, as on the rig.
//
// Stateless: every answer is read from PostgreSQL (several brdf-archive may share one archive, or
// read from replicas). Connections are opened as needed from the conninfo and kept for reuse; one
// that broke (the server restarted) is dropped and the query tried once more on a new one.
// Errors: kNotFound for an unknown session; kDisconnected when the archive cannot be reached;
// kConfigurationError when it refuses the credentials. Messages never hold the conninfo.
// Thread-safe.
#pragma once

#include <cstdint>
#include <functional>
#include <memory>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "core/mutex.h"
#include "core/status.h"
#include "storage/archive/pg.h"
#include "storage/records.h"
#include "storage/session_reader.h"
#include "storage/ship_batch.h"

namespace brdf::storage {

// ListSessions' catalogue filters; an empty field filters nothing.
struct ArchiveSessionQuery {
  std::string rig;       // exactly this rig
  std::string sample;    // the sample's id (exact) or name (case-insensitive)
  std::string material;  // case-insensitive
  std::string tag;       // one of the sample's tags (exact)
  std::vector<SessionState> states;
  std::optional<UnixSeconds> created_after;   // created_at ≥ this
  std::optional<UnixSeconds> created_before;  // created_at < this
  // Paging, newest first: only sessions strictly after this (created_at, id) in that order.
  std::optional<std::pair<UnixSeconds, std::int64_t>> after;
  int limit = 100;  // > 0
};

class ArchiveReader final : public SessionReader {
 public:
  // Connects once (so that a wrong conninfo or an unreachable server is reported at start) and
  // checks the archive's schema: kFailedPrecondition when it is older than this build (a rig of
  // this version, which migrates it, has not shipped yet) or newer.
  static Result<std::shared_ptr<ArchiveReader>> Open(std::string conninfo);

  Result<SessionRecord> GetSession(std::int64_t session) override;
  Result<std::vector<StepRecord>> GetSteps(std::int64_t session) override;
  Result<std::vector<ReadingRecord>> GetReadings(std::int64_t session, std::int64_t after_id,
                                                 int limit) override;
  Result<std::vector<ReadingPointRecord>> GetReadingPoints(std::int64_t session,
                                                           std::int64_t after_id,
                                                           int limit) override;
  // The events shipped so far (schema v3's session_events), in the rig's order.
  Result<std::vector<SessionEventRecord>> ListSessionEvents(std::int64_t session) override;
  // The devices shipped with the session, in the rig's order (ids the rig's; session_id this
  // archive's id).
  Result<std::vector<DeviceRecord>> GetSessionDevices(std::int64_t session) override;
  // The adaptive rounds shipped so far (schema v5), oldest first, with what each meant for the
  // budget as the rig computed it; empty for a session without rounds (another kind of plan, or
  // none stored yet). Each record's session_id is this archive's id.
  Result<std::vector<ArchivedRound>> GetRounds(std::int64_t session);
  // True when the session has ended (completed, aborted, failed) and the reading of every
  // measuring step it did is in the archive: nothing more will arrive.
  Result<bool> Finished(std::int64_t session);
  // Sessions matching `query`, newest first (created_at, then id, descending).
  Result<std::vector<SessionRecord>> ListSessions(const ArchiveSessionQuery& query);

 private:
  explicit ArchiveReader(std::string conninfo) : conninfo_(std::move(conninfo)) {}
  // A page of `session`'s readings (GetReadings, GetReadingPoints): the prepared `statement`'s
  // rows, each turned into a Record by `read`; kNotFound when the session is not archived.
  template <typename Record>
  Result<std::vector<Record>> ReadingPage(std::int64_t session, std::int64_t after_id, int limit,
                                          const char* statement, std::string_view query,
                                          Result<Record> (*read)(const PgResult&, int,
                                                                 std::int64_t));
  // Runs `work` on a pooled connection; once more on a fresh one when the connection broke.
  Status WithConnection(const std::function<Status(PgConnection&)>& work);

  const std::string conninfo_;
  Mutex mu_;
  std::vector<std::unique_ptr<PgConnection>> idle_ GUARDED_BY(mu_);
};

}  // namespace brdf::storage
