#include "daemon/archive/catalogue.h"

#include <cinttypes>
#include <cstdio>
#include <cstdlib>
#include <string>
#include <utility>
#include <vector>

#include "daemon/api/common.h"
#include "daemon/sessions/session_plan.h"
#include "daemon/wire/round.h"
#include "daemon/wire/session.h"

namespace brdf::daemon {
namespace {

// How often StreamReadings with follow looks for readings newly shipped to the archive.
constexpr std::chrono::milliseconds kArchivePollInterval{1000};

// The page token: the last session's created_at (17 significant digits: exact) and archive id.
std::string PageToken(const storage::SessionRecord& last) {
  char text[64];
  std::snprintf(text, sizeof text, "%.17g/%" PRId64, last.created_at, last.id);
  return text;
}

bool ParsePageToken(const std::string& token, std::pair<double, std::int64_t>* out) {
  if (token.size() > 64) return false;
  const std::size_t slash = token.find('/');
  if (slash == std::string::npos || slash == 0 || slash + 1 == token.size()) return false;
  const std::string at = token.substr(0, slash);
  const std::string id = token.substr(slash + 1);
  char* end = nullptr;
  const double seconds = std::strtod(at.c_str(), &end);
  if (end != at.c_str() + at.size()) return false;
  end = nullptr;
  const long long number = std::strtoll(id.c_str(), &end, 10);
  if (end != id.c_str() + id.size() || number <= 0) return false;
  *out = {seconds, number};
  return true;
}

// The API's Session for an archived record: with its plan when `with_plan`, progress from
// `steps` when given (else only the step counts).
v1::Session ArchivedSession(const storage::SessionRecord& record,
                            const std::vector<storage::StepRecord>* steps, bool with_plan) {
  SessionFacts facts(record);
  // A plan that does not parse is shown as none, as on the rig.
  Result<SessionPlan> plan = ParseSessionPlan(record);
  facts.plan = plan.ok() ? &*plan : nullptr;
  facts.with_plan = with_plan;
  facts.steps = steps;
  return ToProtoSession(facts);
}

}  // namespace

Result<v1::Session> ArchiveCatalogue::GetSession(SessionId session) {
  BRDF_ASSIGN_OR_RETURN(storage::SessionRecord record, archive_->GetSession(session));
  BRDF_ASSIGN_OR_RETURN(std::vector<storage::StepRecord> steps, archive_->GetSteps(session));
  return ArchivedSession(record, &steps, /*with_plan=*/true);
}

Result<SessionPage> ArchiveCatalogue::ListSessions(const CatalogueFilter& filter,
                                                   const std::string& page_token,
                                                   std::uint32_t page_size) {
  storage::ArchiveSessionQuery query;
  query.states = filter.states;
  query.rig = filter.rig;
  query.sample = filter.sample;
  query.material = filter.material;
  query.tag = filter.tag;
  query.created_after = filter.created_after;
  query.created_before = filter.created_before;
  if (!page_token.empty()) {
    std::pair<double, std::int64_t> after;
    if (!ParsePageToken(page_token, &after)) {
      return InvalidArgument(
          "page_token: not a token this archive gave out; pass next_page_token as it was "
          "returned, or leave it empty for the first page");
    }
    query.after = after;
  }
  query.limit = static_cast<int>(page_size) + 1;  // one more: is there a next page?
  BRDF_ASSIGN_OR_RETURN(std::vector<storage::SessionRecord> records, archive_->ListSessions(query));
  const bool more = records.size() > page_size;
  if (more) records.resize(page_size);
  SessionPage page;
  for (const storage::SessionRecord& r : records) {
    page.sessions.push_back(ArchivedSession(r, nullptr, /*with_plan=*/false));
  }
  if (more && !records.empty()) page.next_page_token = PageToken(records.back());
  return page;
}

SessionFollow ArchiveCatalogue::Follow(SessionId session) {
  SessionFollow follow;
  follow.ended = [this, session] { return archive_->Finished(session); };
  follow.wait = [](const StopSignal& stopping, std::int64_t) {
    return stopping.WaitFor(kArchivePollInterval);
  };
  return follow;
}

std::uint32_t ArchiveCatalogue::Averages(SessionId session) {
  Result<storage::SessionRecord> record = archive_->GetSession(session);
  if (!record.ok()) return 0;
  Result<SessionPlan> plan = ParseSessionPlan(*record);
  return plan.ok() ? plan->plan.measurement().averages() : 0;
}

Result<std::vector<v1::AdaptiveRound>> ArchiveCatalogue::AdaptiveRounds(SessionId session) {
  BRDF_ASSIGN_OR_RETURN(std::vector<storage::ArchivedRound> rounds, archive_->GetRounds(session));
  std::vector<v1::AdaptiveRound> out;
  out.reserve(rounds.size());
  for (const storage::ArchivedRound& r : rounds) out.push_back(ToProtoRound(r));
  return out;
}

}  // namespace brdf::daemon
