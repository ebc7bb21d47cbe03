// RigCatalogue: brdfd's sessions as the API reads them (api/session_catalogue.h), from its
// SessionManager (live states, prompts, faults, summaries and ETAs) and its store. Paging is by
// session id, newest first: a page token is the id of the previous page's last session, so pages
// are stable while sessions are added. The streams that follow a session are woken by the
// manager's reading listener as each of its readings is committed, and take the new readings from
// one ReadingFanout (one store read per commit for all of them, api/stream_readings_fanout.h).
#pragma once

#include <chrono>
#include <cstdint>

#include "core/mutex.h"
#include "daemon/api/session_catalogue.h"
#include "daemon/api/stream_readings_fanout.h"
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
  // Ended: the session's state is terminal, as the manager knows it (asked before the page: a
  // session that had ended before the page was read has no reading after it). Waits: until a
  // reading of this session newer than the stream's last is committed, or kFollowIdleWait (to
  // look at the session's state and the client's cancellation), or the server stops.
  SessionFollow Follow(SessionId session) override;
  std::uint32_t Averages(SessionId session) override;

  // How long a follower with nothing new waits before it looks again at its session's state,
  // its client and the server's stop (a reading of its session wakes it at once).
  static constexpr std::chrono::milliseconds kFollowIdleWait{1000};

  // The followers' fan-out (for tests and figures).
  const ReadingFanout& fanout() const { return fanout_; }

 private:
  SessionManager& manager_;
  ReadingFanout fanout_;
  int listener_ = 0;
};

}  // namespace brdf::daemon
