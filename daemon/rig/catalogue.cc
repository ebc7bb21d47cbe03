#include "daemon/rig/catalogue.h"

#include <memory>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "daemon/api/common.h"

namespace brdf::daemon {

RigCatalogue::RigCatalogue(SessionManager& manager)
    : manager_(manager),
      fanout_([&manager](std::int64_t session, std::int64_t after_id, int limit) {
        return manager.store()->GetReadings(session, after_id, limit);
      }) {
  listener_ =
      manager_.AddReadingListener([this](SessionId session, const storage::ReadingRecord& reading) {
        fanout_.Committed(session, reading.id);
      });
}

RigCatalogue::~RigCatalogue() {
  manager_.RemoveReadingListener(listener_);
}

Result<v1::Session> RigCatalogue::GetSession(SessionId session) {
  return manager_.GetSession(session);
}

namespace {

// The session id a page token carries, or kInvalidArgument naming page_token.
Result<std::optional<SessionId>> PageTokenId(const std::string& token) {
  if (token.empty()) return std::optional<SessionId>();
  SessionId id = 0;
  if (ParseSessionIdField(token, "page_token", &id).ok()) return std::optional<SessionId>(id);
  const std::string shown = token.size() <= kMaxSessionIdBytes
                                ? "\"" + PrintablePrefix(token, kMaxSessionIdBytes) + "\""
                                : "the " + std::to_string(token.size()) + "-byte token given";
  return InvalidArgument("page_token: " + shown +
                         " is not a token this daemon gave out; pass next_page_token as it was "
                         "returned, or leave it empty for the first page");
}

}  // namespace

Result<SessionPage> RigCatalogue::ListSessions(const CatalogueFilter& filter,
                                               const std::string& page_token,
                                               std::uint32_t page_size) {
  // Sessions are listed newest (highest id) first, so the next page holds the ids below the
  // token's. Stable under inserts.
  BRDF_ASSIGN_OR_RETURN(std::optional<SessionId> before, PageTokenId(page_token));
  BRDF_ASSIGN_OR_RETURN(std::vector<v1::Session> sessions, manager_.ListSessions(filter.states));
  SessionPage page;
  std::optional<SessionId> last;
  for (v1::Session& s : sessions) {
    Result<SessionId> id = ParseSessionId(s.session_id());
    if (!id.ok()) continue;
    if (before.has_value() && *id >= *before) continue;
    if (!filter.Matches(s)) continue;
    if (page.sessions.size() == page_size) {
      if (last.has_value()) page.next_page_token = std::to_string(*last);
      break;
    }
    last = *id;
    page.sessions.push_back(std::move(s));
  }
  return page;
}

storage::SessionReader& RigCatalogue::reader() {
  return *manager_.store();
}

SessionFollow RigCatalogue::Follow(SessionId session) {
  // The stream follows from now: joined before its first page is read from the store.
  fanout_.Join(session);
  std::shared_ptr<void> joined(nullptr, [this, session](void*) { fanout_.Leave(session); });
  SessionFollow follow;
  // The manager's lock only when a session ended since the last look (endings() is read first:
  // an ending after the look moves it again).
  auto looked = std::make_shared<std::optional<std::uint64_t>>();
  follow.ended = [this, session, joined, looked]() -> Result<bool> {
    const std::uint64_t endings = manager_.endings();
    if (looked->has_value() && **looked == endings) return false;
    BRDF_ASSIGN_OR_RETURN(SessionState now, manager_.State(session));
    *looked = endings;
    return IsTerminal(now);
  };
  follow.wait = [this, session, joined](const StopSignal& stopping, std::int64_t last_id) {
    if (stopping.stopped()) return true;
    fanout_.Wait(session, last_id, kFollowIdleWait);
    return stopping.stopped();
  };
  follow.recent = [this, session, joined](std::int64_t after_id, int limit) {
    return fanout_.After(session, after_id, limit);
  };
  follow.notify = [this, session, joined](std::int64_t last_id, std::function<void()> wake) {
    fanout_.Notify(session, last_id, std::move(wake));
  };
  return follow;
}

std::uint32_t RigCatalogue::Averages(SessionId session) {
  Result<std::shared_ptr<const SessionPlan>> plan = manager_.Plan(session);
  return plan.ok() ? (*plan)->plan.measurement().averages() : 0;
}

}  // namespace brdf::daemon
