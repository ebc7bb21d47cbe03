// The Control service (brdf.proto): plans, sessions, operator verbs, the rig, WatchSession.
// Thin: every RPC authorizes the caller (auth.h), checks its arguments (naming the field), calls
// the SessionManager and maps its Status onto a gRPC code (service_common.h).
#pragma once

#include "brdf/v1/brdf.grpc.pb.h"
#include "daemon/api/common.h"
#include "daemon/engine/session_manager.h"
#include "daemon/rpc/auth.h"
#include "daemon/rpc/control_loop.h"
#include "daemon/rpc/stream_registry.h"

namespace brdf::daemon {

// The control plane's methods, served by ControlLoop (control_loop.h), not the synchronous pool.
using ControlServiceBase =
    v1::Control::WithAsyncMethod_SubmitPlan<v1::Control::WithAsyncMethod_StartSession<
        v1::Control::WithAsyncMethod_PauseSession<v1::Control::WithAsyncMethod_ResumeSession<
            v1::Control::WithAsyncMethod_AbortSession<v1::Control::WithAsyncMethod_AnswerPrompt<
                v1::Control::WithAsyncMethod_GetRigStatus<v1::Control::Service>>>>>>>;

class ControlService final : public ControlServiceBase {
 public:
  // All three must outlive the service. `stopping` ends WatchSession streams at shutdown.
  ControlService(SessionManager& manager, const Authenticator& auth, const StopSignal& stopping,
                 StreamRegistry& streams);

  // Adds the control plane's methods (the operator's verbs and GetRigStatus) to `loop`, which
  // then answers them with the methods below. Before the server is built.
  void ServeOn(ControlLoop& loop);

  grpc::Status SubmitPlan(grpc::ServerContext* context, const v1::SubmitPlanRequest* request,
                          v1::SubmitPlanResponse* response) override;
  grpc::Status ValidatePlan(grpc::ServerContext* context, const v1::ValidatePlanRequest* request,
                            v1::ValidatePlanResponse* response) override;
  grpc::Status StartSession(grpc::ServerContext* context, const v1::StartSessionRequest* request,
                            v1::StartSessionResponse* response) override;
  grpc::Status PauseSession(grpc::ServerContext* context, const v1::PauseSessionRequest* request,
                            v1::PauseSessionResponse* response) override;
  grpc::Status ResumeSession(grpc::ServerContext* context, const v1::ResumeSessionRequest* request,
                             v1::ResumeSessionResponse* response) override;
  grpc::Status AbortSession(grpc::ServerContext* context, const v1::AbortSessionRequest* request,
                            v1::AbortSessionResponse* response) override;
  grpc::Status AnswerPrompt(grpc::ServerContext* context, const v1::AnswerPromptRequest* request,
                            v1::AnswerPromptResponse* response) override;
  grpc::Status GetSession(grpc::ServerContext* context, const v1::GetSessionRequest* request,
                          v1::Session* response) override;
  grpc::Status ListSessions(grpc::ServerContext* context, const v1::ListSessionsRequest* request,
                            v1::ListSessionsResponse* response) override;
  grpc::Status ListSessionEvents(grpc::ServerContext* context,
                                 const v1::ListSessionEventsRequest* request,
                                 v1::ListSessionEventsResponse* response) override;
  grpc::Status GetRigStatus(grpc::ServerContext* context, const v1::GetRigStatusRequest* request,
                            v1::RigStatus* response) override;
  // A snapshot, then every event until the session ends, the client cancels, or the daemon stops
  // (then UNAVAILABLE, after the events already queued were sent).
  grpc::Status WatchSession(grpc::ServerContext* context, const v1::WatchSessionRequest* request,
                            grpc::ServerWriter<v1::SessionEvent>* writer) override;
  // The caller's token's name and role, and "brdfd".
  grpc::Status WhoAmI(grpc::ServerContext* context, const v1::WhoAmIRequest* request,
                      v1::Caller* response) override;

 private:
  SessionManager& manager_;
  const Authenticator& auth_;
  const StopSignal& stopping_;
  StreamRegistry& streams_;
};

}  // namespace brdf::daemon
