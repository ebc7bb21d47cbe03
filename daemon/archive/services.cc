#include "daemon/archive/services.h"

#include <algorithm>
#include <cinttypes>
#include <cstdio>
#include <cstdlib>
#include <string>
#include <utility>
#include <vector>

#include "daemon/api/export_session.h"
#include "daemon/api/stream_readings.h"
#include "daemon/sessions/session_plan.h"
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

}  // namespace

v1::Session ArchivedSession(const storage::SessionRecord& rec,
                            const std::vector<storage::StepRecord>* steps, bool with_plan) {
  SessionFacts facts(rec);
  // A plan that does not parse is shown as none, as on the rig.
  Result<SessionPlan> plan = ParseSessionPlan(rec);
  facts.plan = plan.ok() ? &*plan : nullptr;
  facts.with_plan = with_plan;
  facts.steps = steps;
  return ToProtoSession(facts);
}

// --- Control ------------------------------------------------------------------------------------

ArchiveControlService::ArchiveControlService(std::shared_ptr<storage::ArchiveReader> archive,
                                             const Authenticator& auth)
    : archive_(std::move(archive)), auth_(auth) {}

grpc::Status ArchiveControlService::GetSession(grpc::ServerContext* /*context*/,
                                               const v1::GetSessionRequest* request,
                                               v1::Session* response) {
  SessionId id = 0;
  if (grpc::Status st = ParseSessionIdField(request->session_id(), "session_id", &id); !st.ok()) {
    return st;
  }
  Result<storage::SessionRecord> record = archive_->GetSession(id);
  if (!record.ok()) return ToGrpcStatus(record.status());
  Result<std::vector<storage::StepRecord>> steps = archive_->GetSteps(id);
  if (!steps.ok()) return ToGrpcStatus(steps.status());
  *response = ArchivedSession(*record, &*steps, /*with_plan=*/true);
  return grpc::Status::OK;
}

grpc::Status ArchiveControlService::ListSessionEvents(grpc::ServerContext* /*context*/,
                                                      const v1::ListSessionEventsRequest* request,
                                                      v1::ListSessionEventsResponse* response) {
  return ServeListSessionEvents(*archive_, *request, response);
}

grpc::Status ArchiveControlService::ListSessions(grpc::ServerContext* /*context*/,
                                                 const v1::ListSessionsRequest* request,
                                                 v1::ListSessionsResponse* response) {
  CatalogueFilter filter;
  if (grpc::Status st = ParseCatalogueFilter(*request, &filter); !st.ok()) return st;
  storage::ArchiveSessionQuery query;
  query.states = filter.states;
  query.rig = filter.rig;
  query.sample = filter.sample;
  query.material = filter.material;
  query.tag = filter.tag;
  query.created_after = filter.created_after;
  query.created_before = filter.created_before;
  if (!request->page_token().empty()) {
    std::pair<double, std::int64_t> after;
    if (!ParsePageToken(request->page_token(), &after)) {
      return InvalidField("page_token",
                          "not a token this archive gave out; pass next_page_token as it was "
                          "returned, or leave it empty for the first page");
    }
    query.after = after;
  }
  const std::uint32_t page_size =
      request->page_size() == 0 ? kDefaultPageSize : std::min(request->page_size(), kMaxPageSize);
  query.limit = static_cast<int>(page_size) + 1;  // one more: is there a next page?
  Result<std::vector<storage::SessionRecord>> records = archive_->ListSessions(query);
  if (!records.ok()) return ToGrpcStatus(records.status());
  const bool more = records->size() > page_size;
  if (more) records->resize(page_size);
  for (const storage::SessionRecord& r : *records) {
    *response->add_sessions() = ArchivedSession(r, nullptr, /*with_plan=*/false);
  }
  if (more && !records->empty()) response->set_next_page_token(PageToken(records->back()));
  return grpc::Status::OK;
}

grpc::Status ArchiveControlService::NotHere(const char* method, const std::string& session_id) {
  std::string rig;
  SessionId id = 0;
  if (!session_id.empty() && ParseSessionIdField(session_id, "session_id", &id).ok()) {
    if (Result<storage::SessionRecord> r = archive_->GetSession(id); r.ok()) {
      rig = "rig \"" + r->rig + "\"'s brdfd";
    }
  }
  return grpc::Status(
      grpc::StatusCode::FAILED_PRECONDITION,
      std::string(method) +
          ": this is brdf-archive, the lab archive's read-only server; it "
          "answers sessions, readings and interpolation, never a rig's verbs. Ask " +
          (rig.empty() ? std::string("the rig's brdfd") : rig) + " instead");
}

grpc::Status ArchiveControlService::SubmitPlan(grpc::ServerContext* /*context*/,
                                               const v1::SubmitPlanRequest*,
                                               v1::SubmitPlanResponse*) {
  return NotHere("SubmitPlan", "");
}
grpc::Status ArchiveControlService::ValidatePlan(grpc::ServerContext* /*context*/,
                                                 const v1::ValidatePlanRequest*,
                                                 v1::ValidatePlanResponse*) {
  return NotHere("ValidatePlan", "");
}
grpc::Status ArchiveControlService::StartSession(grpc::ServerContext* /*context*/,
                                                 const v1::StartSessionRequest* request,
                                                 v1::StartSessionResponse*) {
  return NotHere("StartSession", request->session_id());
}
grpc::Status ArchiveControlService::PauseSession(grpc::ServerContext* /*context*/,
                                                 const v1::PauseSessionRequest* request,
                                                 v1::PauseSessionResponse*) {
  return NotHere("PauseSession", request->session_id());
}
grpc::Status ArchiveControlService::ResumeSession(grpc::ServerContext* /*context*/,
                                                  const v1::ResumeSessionRequest* request,
                                                  v1::ResumeSessionResponse*) {
  return NotHere("ResumeSession", request->session_id());
}
grpc::Status ArchiveControlService::AbortSession(grpc::ServerContext* /*context*/,
                                                 const v1::AbortSessionRequest* request,
                                                 v1::AbortSessionResponse*) {
  return NotHere("AbortSession", request->session_id());
}
grpc::Status ArchiveControlService::AnswerPrompt(grpc::ServerContext* /*context*/,
                                                 const v1::AnswerPromptRequest* request,
                                                 v1::AnswerPromptResponse*) {
  return NotHere("AnswerPrompt", request->session_id());
}
grpc::Status ArchiveControlService::GetRigStatus(grpc::ServerContext* /*context*/,
                                                 const v1::GetRigStatusRequest*, v1::RigStatus*) {
  return NotHere("GetRigStatus", "");
}
grpc::Status ArchiveControlService::WatchSession(grpc::ServerContext* /*context*/,
                                                 const v1::WatchSessionRequest* request,
                                                 grpc::ServerWriter<v1::SessionEvent>*) {
  return NotHere("WatchSession", request->session_id());
}

// --- Data ---------------------------------------------------------------------------------------

ArchiveDataService::ArchiveDataService(std::shared_ptr<storage::ArchiveReader> archive,
                                       const Authenticator& auth, const StopSignal& stopping,
                                       StreamRegistry& streams)
    : archive_(std::move(archive)), auth_(auth), stopping_(stopping), streams_(streams) {}

grpc::Status ArchiveDataService::StreamReadings(grpc::ServerContext* context,
                                                const v1::StreamReadingsRequest* request,
                                                grpc::ServerWriter<v1::Reading>* writer) {
  return Serve(*context, *request, "StreamReadings",
               [&](StreamReadingsCall& call, const ReadingSource& source) {
                 return StreamSessionReadings(*context, *request, call, source, writer);
               });
}

grpc::Status ArchiveDataService::StreamReadingPoints(
    grpc::ServerContext* context, const v1::StreamReadingsRequest* request,
    grpc::ServerWriter<v1::ReadingPoints>* writer) {
  return Serve(*context, *request, "StreamReadingPoints",
               [&](StreamReadingsCall& call, const ReadingSource& source) {
                 return StreamSessionReadingPoints(*context, *request, call, source, writer);
               });
}

grpc::Status ArchiveDataService::Serve(grpc::ServerContext& context,
                                       const v1::StreamReadingsRequest& request, const char* rpc,
                                       const ReadingStreamBody& body) {
  StreamReadingsCall call;
  if (grpc::Status st = CheckStreamReadings(context, request, rpc, auth_, streams_, &call);
      !st.ok()) {
    return st;
  }
  Result<storage::SessionRecord> session = archive_->GetSession(call.session);
  if (!session.ok()) return ToGrpcStatus(session.status());
  ReadingSource source;
  source.reader = archive_.get();
  // Ended is not enough: a rig ships a session's state before its last readings.
  source.ended = [&] { return archive_->Finished(call.session); };
  source.wait = [&] { return stopping_.WaitFor(kArchivePollInterval); };
  source.server = "brdf-archive";
  source.extras = [&] {
    std::uint32_t averages = 0;
    if (Result<SessionPlan> plan = ParseSessionPlan(*session); plan.ok()) {
      averages = plan->plan.measurement().averages();
    }
    return ReadingExtrasOf(*archive_, call.session, averages);
  };
  return body(call, source);
}

grpc::Status ArchiveDataService::Export(grpc::ServerContext* context,
                                        const v1::ExportRequest* request,
                                        grpc::ServerWriter<v1::ExportChunk>* writer) {
  return ExportSession(*context, *request, *writer, auth_, streams_, stopping_, *archive_);
}

grpc::Status ArchiveControlService::WhoAmI(grpc::ServerContext* context,
                                           const v1::WhoAmIRequest* /*request*/,
                                           v1::Caller* response) {
  return ServeWhoAmI(auth_, *context, "brdf-archive", response);
}

}  // namespace brdf::daemon
