// ArchiveCatalogue: the lab archive's sessions as the API reads them (api/session_catalogue.h),
// across rigs, from storage/archive/reader.h. A session here carries what the archive holds: no
// plan summary or ETA (they need the rig's description), last_quality_code −1, no live prompt or
// fault. Paging is newest first by (created_at, archive id), the filters in the archive's SQL. A
// stream that follows a session polls the archive for readings newly shipped until the rig has
// shipped the session's end.
#pragma once

#include <memory>

#include "daemon/api/session_catalogue.h"
#include "storage/archive/reader.h"

namespace brdf::daemon {

class ArchiveCatalogue final : public SessionCatalogue {
 public:
  explicit ArchiveCatalogue(std::shared_ptr<storage::ArchiveReader> archive)
      : archive_(std::move(archive)) {}

  Result<v1::Session> GetSession(SessionId session) override;
  Result<SessionPage> ListSessions(const CatalogueFilter& filter, const std::string& page_token,
                                   std::uint32_t page_size) override;
  storage::SessionReader& reader() override { return *archive_; }
  // Ended: the archive holds the session's end and every reading (a rig ships a session's state
  // before its last readings). Waits: a second, or until stopping.
  SessionFollow Follow(SessionId session) override;
  std::uint32_t Averages(SessionId session) override;
  // The rounds the rigs shipped (archive schema v5), each with the spend its rig computed.
  Result<std::vector<v1::AdaptiveRound>> AdaptiveRounds(SessionId session) override;

 private:
  std::shared_ptr<storage::ArchiveReader> archive_;
};

}  // namespace brdf::daemon
