// RigCatalogue: brdfd's sessions as the API reads them (api/session_catalogue.h), from its
// SessionManager (live states, prompts, faults, summaries and ETAs) and its store. Paging is by
// session id, newest first: a page token is the id of the previous page's last session, so pages
// are stable while sessions are added. A stream that follows a session is woken by the manager's
// reading listener as each reading is committed.
#pragma once

#include <cstdint>

#include "core/mutex.h"
#include "daemon/api/session_catalogue.h"
#include "daemon/engine/session_manager.h"

namespace brdf::daemon {

class RigCatalogue final : public SessionCatalogue {
 public:
  // Registers a reading listener on `manager` (removed by the destructor); `manager` must
  // outlive the catalogue.
  explicit RigCatalogue(SessionManager& manager);
  ~RigCatalogue() override;
  RigCatalogue(const RigCatalogue&) = delete;
  RigCatalogue& operator=(const RigCatalogue&) = delete;

  Result<v1::Session> GetSession(SessionId session) override;
  Result<SessionPage> ListSessions(const CatalogueFilter& filter, const std::string& page_token,
                                   std::uint32_t page_size) override;
  storage::SessionReader& reader() override;
  // Ended: the session's state is terminal (read before the page: a session that had ended
  // before the page was read has no reading after it). Waits: until the next commit, or
  // kStreamPollInterval.
  SessionFollow Follow(SessionId session) override;
  std::uint32_t Averages(SessionId session) override;

 private:
  // Counts the readings committed (any session); followers wait for it to move.
  std::uint64_t Generation() const;
  void WaitForReading(std::uint64_t seen, std::chrono::steady_clock::duration d,
                      const StopSignal& stopping) const;

  SessionManager& manager_;
  int listener_ = 0;
  mutable Mutex mu_;
  mutable CondVar cv_;
  std::uint64_t generation_ GUARDED_BY(mu_) = 0;
};

}  // namespace brdf::daemon
