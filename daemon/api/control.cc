#include "daemon/api/control.h"

#include <spdlog/spdlog.h>

#include <algorithm>
#include <cmath>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "daemon/wire/enums.h"
#include "daemon/wire/plan.h"

namespace brdf::daemon {

ControlService::ControlService(SessionManager& manager, const Authenticator& auth,
                               const StopSignal& stopping, StreamRegistry& streams)
    : manager_(manager), auth_(auth), stopping_(stopping), streams_(streams) {}

void ControlService::ServeOn(ControlLoop& loop) {
  // Each method's async request (RequestX) and its handler (X), by name.
#define BRDF_CONTROL_METHOD(Name, Req, Resp)                                                    \
  loop.Add<v1::Req, v1::Resp>(                                                                  \
      [this](grpc::ServerContext* c, v1::Req* r, grpc::ServerAsyncResponseWriter<v1::Resp>* w,  \
             grpc::ServerCompletionQueue* q, void* tag) { Request##Name(c, r, w, q, q, tag); }, \
      [this](grpc::ServerContext* c, const v1::Req* r, v1::Resp* out) { return Name(c, r, out); })
  BRDF_CONTROL_METHOD(SubmitPlan, SubmitPlanRequest, SubmitPlanResponse);
  BRDF_CONTROL_METHOD(StartSession, StartSessionRequest, StartSessionResponse);
  BRDF_CONTROL_METHOD(PauseSession, PauseSessionRequest, PauseSessionResponse);
  BRDF_CONTROL_METHOD(ResumeSession, ResumeSessionRequest, ResumeSessionResponse);
  BRDF_CONTROL_METHOD(AbortSession, AbortSessionRequest, AbortSessionResponse);
  BRDF_CONTROL_METHOD(AnswerPrompt, AnswerPromptRequest, AnswerPromptResponse);
  BRDF_CONTROL_METHOD(GetRigStatus, GetRigStatusRequest, RigStatus);
#undef BRDF_CONTROL_METHOD
}

namespace {

// The session id of a request, or INVALID_ARGUMENT naming the field.
grpc::Status ParseId(const std::string& text, SessionId* id) {
  return ParseSessionIdField(text, "session_id", id);
}

grpc::Status CheckNote(const std::string& text, const std::string& field) {
  if (text.size() > kMaxNoteBytes) {
    return InvalidField(field, "too long (" + std::to_string(text.size()) + " bytes; at most " +
                                   std::to_string(kMaxNoteBytes) + ")");
  }
  return grpc::Status::OK;
}

}  // namespace

grpc::Status ControlService::SubmitPlan(grpc::ServerContext* context,
                                        const v1::SubmitPlanRequest* request,
                                        v1::SubmitPlanResponse* response) {
  Caller caller;
  if (grpc::Status st = auth_.CallerOf(*context, &caller); !st.ok()) return st;
  if (!request->has_plan()) {
    return InvalidField("plan", "missing; give the plan to run (see ValidatePlan)");
  }
  Result<v1::Session> session =
      manager_.SubmitPlan(request->plan(), caller.ToActor(), request->start_now());
  if (!session.ok()) return ToGrpcStatus(session.status());
  *response->mutable_session() = std::move(*session);
  return grpc::Status::OK;
}

grpc::Status ControlService::ValidatePlan(grpc::ServerContext* /*context*/,
                                          const v1::ValidatePlanRequest* request,
                                          v1::ValidatePlanResponse* response) {
  if (!request->has_plan()) {
    return InvalidField("plan", "missing; give the plan to check");
  }
  const double time_scale = request->time_scale();
  if (!std::isfinite(time_scale) || time_scale < 0) {
    return InvalidField("time_scale", "must be a positive number (0 or unset: 1, a real rig)");
  }
  *response = ToValidatePlanResponse(
      manager_.ValidatePlan(request->plan(), time_scale > 0 ? time_scale : 1));
  return grpc::Status::OK;
}

grpc::Status ControlService::StartSession(grpc::ServerContext* context,
                                          const v1::StartSessionRequest* request,
                                          v1::StartSessionResponse* response) {
  Caller caller;
  if (grpc::Status st = auth_.CallerOf(*context, &caller); !st.ok()) return st;
  SessionId id = 0;
  if (grpc::Status st = ParseId(request->session_id(), &id); !st.ok()) return st;
  Result<v1::Session> session = manager_.Start(id, caller.ToActor());
  if (!session.ok()) return ToGrpcStatus(session.status());
  *response->mutable_session() = std::move(*session);
  return grpc::Status::OK;
}

grpc::Status ControlService::PauseSession(grpc::ServerContext* context,
                                          const v1::PauseSessionRequest* request,
                                          v1::PauseSessionResponse* response) {
  Caller caller;
  if (grpc::Status st = auth_.CallerOf(*context, &caller); !st.ok()) return st;
  SessionId id = 0;
  if (grpc::Status st = ParseId(request->session_id(), &id); !st.ok()) return st;
  const std::optional<PauseMode> mode = FromProtoPauseMode(request->mode());
  if (!mode.has_value()) {
    return InvalidField("mode", "unknown pause mode " + std::to_string(request->mode()) +
                                    "; use PAUSE_MODE_DEFERRED or PAUSE_MODE_IMMEDIATE");
  }
  Result<v1::Session> before = manager_.GetSession(id);
  Result<v1::Session> session = manager_.Pause(id, *mode, caller.ToActor());
  if (!session.ok()) return ToGrpcStatus(session.status());
  response->set_already_paused(before.ok() && before->state() == v1::SESSION_STATE_PAUSED &&
                               session->state() == v1::SESSION_STATE_PAUSED);
  *response->mutable_session() = std::move(*session);
  return grpc::Status::OK;
}

grpc::Status ControlService::ResumeSession(grpc::ServerContext* context,
                                           const v1::ResumeSessionRequest* request,
                                           v1::ResumeSessionResponse* response) {
  Caller caller;
  if (grpc::Status st = auth_.CallerOf(*context, &caller); !st.ok()) return st;
  SessionId id = 0;
  if (grpc::Status st = ParseId(request->session_id(), &id); !st.ok()) return st;
  Result<v1::Session> session = manager_.Resume(id, caller.ToActor());
  if (!session.ok()) return ToGrpcStatus(session.status());
  *response->mutable_session() = std::move(*session);
  return grpc::Status::OK;
}

grpc::Status ControlService::AbortSession(grpc::ServerContext* context,
                                          const v1::AbortSessionRequest* request,
                                          v1::AbortSessionResponse* response) {
  Caller caller;
  if (grpc::Status st = auth_.CallerOf(*context, &caller); !st.ok()) return st;
  SessionId id = 0;
  if (grpc::Status st = ParseId(request->session_id(), &id); !st.ok()) return st;
  if (grpc::Status st = CheckNote(request->reason(), "reason"); !st.ok()) return st;
  const std::string reason =
      request->reason().empty() ? "aborted by " + caller.name : request->reason();
  Result<v1::Session> session = manager_.Abort(id, reason, caller.ToActor());
  if (!session.ok()) return ToGrpcStatus(session.status());
  *response->mutable_session() = std::move(*session);
  return grpc::Status::OK;
}

grpc::Status ControlService::AnswerPrompt(grpc::ServerContext* context,
                                          const v1::AnswerPromptRequest* request,
                                          v1::AnswerPromptResponse* response) {
  Caller caller;
  if (grpc::Status st = auth_.CallerOf(*context, &caller); !st.ok()) return st;
  SessionId id = 0;
  if (grpc::Status st = ParseId(request->session_id(), &id); !st.ok()) return st;
  if (request->step_index() < 0) {
    return InvalidField("step_index", "must be ≥ 0 (got " + std::to_string(request->step_index()) +
                                          "); give the pending prompt's Prompt.step_index");
  }
  if (grpc::Status st = CheckNote(request->note(), "note"); !st.ok()) return st;
  Result<v1::Session> session =
      manager_.AnswerPrompt(id, request->step_index(), request->note(), caller.ToActor());
  if (!session.ok()) return ToGrpcStatus(session.status());
  *response->mutable_session() = std::move(*session);
  return grpc::Status::OK;
}

grpc::Status ControlService::GetSession(grpc::ServerContext* /*context*/,
                                        const v1::GetSessionRequest* request,
                                        v1::Session* response) {
  SessionId id = 0;
  if (grpc::Status st = ParseId(request->session_id(), &id); !st.ok()) return st;
  Result<v1::Session> session = manager_.GetSession(id);
  if (!session.ok()) return ToGrpcStatus(session.status());
  *response = std::move(*session);
  return grpc::Status::OK;
}

grpc::Status ControlService::ListSessionEvents(grpc::ServerContext* /*context*/,
                                               const v1::ListSessionEventsRequest* request,
                                               v1::ListSessionEventsResponse* response) {
  return ServeListSessionEvents(*manager_.store(), *request, response);
}

grpc::Status ControlService::ListSessions(grpc::ServerContext* /*context*/,
                                          const v1::ListSessionsRequest* request,
                                          v1::ListSessionsResponse* response) {
  CatalogueFilter filter;
  if (grpc::Status st = ParseCatalogueFilter(*request, &filter); !st.ok()) return st;
  // The page token is the id of the last session of the previous page: sessions are listed
  // newest (highest id) first, so the next page holds the ids below it. Stable under inserts.
  std::optional<SessionId> before;
  if (!request->page_token().empty()) {
    SessionId token = 0;
    if (!ParseSessionIdField(request->page_token(), "page_token", &token).ok()) {
      const std::string shown =
          request->page_token().size() <= kMaxSessionIdBytes
              ? "\"" + PrintablePrefix(request->page_token(), kMaxSessionIdBytes) + "\""
              : "the " + std::to_string(request->page_token().size()) + "-byte token given";
      return InvalidField("page_token",
                          shown +
                              " is not a token this daemon gave out; pass next_page_token as it "
                              "was returned, or leave it empty for the first page");
    }
    before = token;
  }
  const std::uint32_t page_size =
      request->page_size() == 0 ? kDefaultPageSize : std::min(request->page_size(), kMaxPageSize);

  Result<std::vector<v1::Session>> sessions = manager_.ListSessions(filter.states);
  if (!sessions.ok()) return ToGrpcStatus(sessions.status());
  std::optional<SessionId> last;
  bool more = false;
  for (v1::Session& s : *sessions) {
    Result<SessionId> id = ParseSessionId(s.session_id());
    if (!id.ok()) continue;
    if (before.has_value() && *id >= *before) continue;
    if (!filter.Matches(s)) continue;
    if (static_cast<std::uint32_t>(response->sessions_size()) == page_size) {
      more = true;
      break;
    }
    last = *id;
    *response->add_sessions() = std::move(s);
  }
  if (more && last.has_value()) response->set_next_page_token(std::to_string(*last));
  return grpc::Status::OK;
}

grpc::Status ControlService::GetRigStatus(grpc::ServerContext* /*context*/,
                                          const v1::GetRigStatusRequest* /*request*/,
                                          v1::RigStatus* response) {
  *response = manager_.GetRigStatus();
  return grpc::Status::OK;
}

grpc::Status ControlService::WatchSession(grpc::ServerContext* context,
                                          const v1::WatchSessionRequest* request,
                                          grpc::ServerWriter<v1::SessionEvent>* writer) {
  Caller caller;
  if (grpc::Status st = auth_.CallerOf(*context, &caller); !st.ok()) return st;
  std::unique_ptr<StreamRegistry::Slot> slot;
  if (grpc::Status st = streams_.Open(*context, &caller, "WatchSession", &slot); !st.ok()) {
    return st;
  }
  SessionId id = 0;
  if (grpc::Status st = ParseId(request->session_id(), &id); !st.ok()) return st;
  Result<std::shared_ptr<EventSubscription>> subscribed = manager_.Subscribe(id);
  if (!subscribed.ok()) return ToGrpcStatus(subscribed.status());
  const std::shared_ptr<EventSubscription> sub = *subscribed;
  spdlog::debug("WatchSession: {} watches session {}", caller.name, id);

  for (;;) {
    if (context->IsCancelled()) {
      sub->Close();
      return grpc::Status(grpc::StatusCode::CANCELLED, "WatchSession: cancelled by the client");
    }
    // At shutdown, send what is queued (the pause the shutdown made, typically), then end.
    const bool stopping = stopping_.stopped();
    std::optional<v1::SessionEvent> event =
        sub->Next(stopping ? std::chrono::milliseconds(0) : kStreamPollInterval);
    if (event.has_value()) {
      if (!slot->Write(writer, *event)) {
        sub->Close();
        return grpc::Status(grpc::StatusCode::CANCELLED, "WatchSession: the client went away");
      }
      continue;
    }
    if (sub->ended()) return grpc::Status::OK;
    if (stopping) {
      sub->Close();
      return grpc::Status(grpc::StatusCode::UNAVAILABLE,
                          "WatchSession: the daemon is shutting down; watch again once it is "
                          "back (the session is kept)");
    }
  }
}

grpc::Status ControlService::WhoAmI(grpc::ServerContext* context,
                                    const v1::WhoAmIRequest* /*request*/, v1::Caller* response) {
  return ServeWhoAmI(auth_, *context, "brdfd", response);
}

}  // namespace brdf::daemon
