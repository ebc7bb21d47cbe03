#include "daemon/api/control.h"

#include <spdlog/spdlog.h>

#include <chrono>
#include <cmath>
#include <memory>
#include <optional>
#include <string>
#include <utility>

#include "daemon/wire/enums.h"
#include "daemon/wire/plan.h"

namespace brdf::daemon {

ControlService::ControlService(SessionCatalogue& catalogue, RigPort* rig, const Authenticator& auth,
                               const StopSignal& stopping, StreamRegistry& streams,
                               StreamPump& pump, std::string program)
    : catalogue_(catalogue),
      rig_(rig),
      auth_(auth),
      stopping_(stopping),
      streams_(streams),
      pump_(pump),
      program_(std::move(program)) {}

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

grpc::Status ControlService::NoRig(const char* method, const std::string& session_id) {
  std::string rig;
  SessionId id = 0;
  if (!session_id.empty() && ParseSessionIdField(session_id, "session_id", &id).ok()) {
    if (Result<v1::Session> s = catalogue_.GetSession(id); s.ok()) {
      rig = "rig \"" + s->rig() + "\"'s brdfd";
    }
  }
  return grpc::Status(
      grpc::StatusCode::FAILED_PRECONDITION,
      std::string(method) +
          ": this is brdf-archive, the lab archive's read-only server; it "
          "answers sessions, readings and interpolation, never a rig's verbs. Ask " +
          (rig.empty() ? std::string("the rig's brdfd") : rig) + " instead");
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

// The session a verb returned, into its response, or the verb's error.
template <typename Response>
grpc::Status Answer(Result<v1::Session> session, Response* response) {
  if (!session.ok()) return ToGrpcStatus(session.status());
  *response->mutable_session() = std::move(*session);
  return grpc::Status::OK;
}

}  // namespace

grpc::Status ControlService::SubmitPlan(grpc::ServerContext* context,
                                        const v1::SubmitPlanRequest* request,
                                        v1::SubmitPlanResponse* response) {
  if (rig_ == nullptr) return NoRig("SubmitPlan", "");
  Caller caller;
  if (grpc::Status st = auth_.CallerOf(*context, &caller); !st.ok()) return st;
  if (!request->has_plan()) {
    return InvalidField("plan", "missing; give the plan to run (see ValidatePlan)");
  }
  return Answer(rig_->SubmitPlan(request->plan(), caller.ToActor(), request->start_now()),
                response);
}

grpc::Status ControlService::ValidatePlan(grpc::ServerContext* /*context*/,
                                          const v1::ValidatePlanRequest* request,
                                          v1::ValidatePlanResponse* response) {
  if (rig_ == nullptr) return NoRig("ValidatePlan", "");
  if (!request->has_plan()) {
    return InvalidField("plan", "missing; give the plan to check");
  }
  const double time_scale = request->time_scale();
  if (!std::isfinite(time_scale) || time_scale < 0) {
    return InvalidField("time_scale",
                        "must be a finite number > 0, or 0 (unset) for this rig's own ([rig] "
                        "time_scale; 1 on a real rig) (got " +
                            ShortNumber(time_scale) + ")");
  }
  *response = ToValidatePlanResponse(rig_->ValidatePlan(request->plan(), time_scale));
  return grpc::Status::OK;
}

grpc::Status ControlService::StartSession(grpc::ServerContext* context,
                                          const v1::StartSessionRequest* request,
                                          v1::StartSessionResponse* response) {
  if (rig_ == nullptr) return NoRig("StartSession", request->session_id());
  Caller caller;
  if (grpc::Status st = auth_.CallerOf(*context, &caller); !st.ok()) return st;
  SessionId id = 0;
  if (grpc::Status st = ParseId(request->session_id(), &id); !st.ok()) return st;
  return Answer(rig_->Start(id, caller.ToActor()), response);
}

grpc::Status ControlService::PauseSession(grpc::ServerContext* context,
                                          const v1::PauseSessionRequest* request,
                                          v1::PauseSessionResponse* response) {
  if (rig_ == nullptr) return NoRig("PauseSession", request->session_id());
  Caller caller;
  if (grpc::Status st = auth_.CallerOf(*context, &caller); !st.ok()) return st;
  SessionId id = 0;
  if (grpc::Status st = ParseId(request->session_id(), &id); !st.ok()) return st;
  const std::optional<PauseMode> mode = FromProtoPauseMode(request->mode());
  if (!mode.has_value()) {
    return InvalidField("mode", "unknown pause mode " + std::to_string(request->mode()) +
                                    "; use PAUSE_MODE_DEFERRED or PAUSE_MODE_IMMEDIATE");
  }
  // Whether it was paused before comes from the rig's own state as the verb ran: no read of the
  // session before the verb (1.5 ms of 3.4 idle, more under the analysts' reads).
  bool was_paused = false;
  Result<v1::Session> session = rig_->Pause(id, *mode, caller.ToActor(), &was_paused);
  if (!session.ok()) return ToGrpcStatus(session.status());
  response->set_already_paused(was_paused && session->state() == v1::SESSION_STATE_PAUSED);
  *response->mutable_session() = std::move(*session);
  return grpc::Status::OK;
}

grpc::Status ControlService::ResumeSession(grpc::ServerContext* context,
                                           const v1::ResumeSessionRequest* request,
                                           v1::ResumeSessionResponse* response) {
  if (rig_ == nullptr) return NoRig("ResumeSession", request->session_id());
  Caller caller;
  if (grpc::Status st = auth_.CallerOf(*context, &caller); !st.ok()) return st;
  SessionId id = 0;
  if (grpc::Status st = ParseId(request->session_id(), &id); !st.ok()) return st;
  return Answer(rig_->Resume(id, caller.ToActor()), response);
}

grpc::Status ControlService::AbortSession(grpc::ServerContext* context,
                                          const v1::AbortSessionRequest* request,
                                          v1::AbortSessionResponse* response) {
  if (rig_ == nullptr) return NoRig("AbortSession", request->session_id());
  Caller caller;
  if (grpc::Status st = auth_.CallerOf(*context, &caller); !st.ok()) return st;
  SessionId id = 0;
  if (grpc::Status st = ParseId(request->session_id(), &id); !st.ok()) return st;
  if (grpc::Status st = CheckNote(request->reason(), "reason"); !st.ok()) return st;
  const std::string reason =
      request->reason().empty() ? "aborted by " + caller.name : request->reason();
  return Answer(rig_->Abort(id, reason, caller.ToActor()), response);
}

grpc::Status ControlService::AnswerPrompt(grpc::ServerContext* context,
                                          const v1::AnswerPromptRequest* request,
                                          v1::AnswerPromptResponse* response) {
  if (rig_ == nullptr) return NoRig("AnswerPrompt", request->session_id());
  Caller caller;
  if (grpc::Status st = auth_.CallerOf(*context, &caller); !st.ok()) return st;
  SessionId id = 0;
  if (grpc::Status st = ParseId(request->session_id(), &id); !st.ok()) return st;
  if (request->step_index() < 0) {
    return InvalidField("step_index", "must be ≥ 0 (got " + std::to_string(request->step_index()) +
                                          "); give the pending prompt's Prompt.step_index");
  }
  if (grpc::Status st = CheckNote(request->note(), "note"); !st.ok()) return st;
  return Answer(rig_->AnswerPrompt(id, request->step_index(), request->note(), caller.ToActor()),
                response);
}

grpc::Status ControlService::GetRigStatus(grpc::ServerContext* /*context*/,
                                          const v1::GetRigStatusRequest* /*request*/,
                                          v1::RigStatus* response) {
  if (rig_ == nullptr) return NoRig("GetRigStatus", "");
  *response = rig_->GetRigStatus();
  return grpc::Status::OK;
}

grpc::Status ControlService::ListAdaptiveRounds(grpc::ServerContext* /*context*/,
                                                const v1::ListAdaptiveRoundsRequest* request,
                                                v1::ListAdaptiveRoundsResponse* response) {
  SessionId id = 0;
  if (grpc::Status st = ParseSessionIdField(request->session_id(), "session_id", &id); !st.ok()) {
    return st;
  }
  // brdfd: its store; brdf-archive: the rounds the rigs shipped.
  Result<std::vector<v1::AdaptiveRound>> rounds =
      rig_ != nullptr ? rig_->AdaptiveRounds(id) : catalogue_.AdaptiveRounds(id);
  if (!rounds.ok()) return ToGrpcStatus(rounds.status());
  response->mutable_rounds()->Reserve(static_cast<int>(rounds->size()));
  for (v1::AdaptiveRound& r : *rounds) *response->add_rounds() = std::move(r);
  return grpc::Status::OK;
}

}  // namespace brdf::daemon
