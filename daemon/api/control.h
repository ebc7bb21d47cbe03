// The Control service (brdf.proto), once for brdfd and brdf-archive: the sessions read from a
// SessionCatalogue (GetSession, ListSessions with the catalogue filters and paging,
// ListSessionEvents), WhoAmI, and the rig's verbs, GetRigStatus and WatchSession through the
// server's RigPort. A server without a rig (brdf-archive) answers those FAILED_PRECONDITION,
// naming the session's rig as the place to ask. Thin: the token gate admitted the call; each RPC
// checks its arguments (naming the field), calls the catalogue or the rig, and maps its Status
// onto a gRPC code (common.h).
#pragma once

#include <string>

#include "brdf/v1/brdf.grpc.pb.h"
#include "daemon/api/common.h"
#include "daemon/api/rig_port.h"
#include "daemon/api/session_catalogue.h"
#include "daemon/api/stream_pump.h"
#include "daemon/rpc/auth.h"
#include "daemon/rpc/control_loop.h"
#include "daemon/rpc/stream_registry.h"

namespace brdf::daemon {

// The control plane's methods, served by ControlLoop (control_loop.h), not the synchronous pool;
// WatchSession on gRPC's callback API (the stream pump: a watch that waits holds no thread).
using ControlServiceBase = v1::Control::WithAsyncMethod_SubmitPlan<
    v1::Control::WithAsyncMethod_StartSession<v1::Control::WithAsyncMethod_PauseSession<
        v1::Control::WithAsyncMethod_ResumeSession<v1::Control::WithAsyncMethod_AbortSession<
            v1::Control::WithAsyncMethod_AnswerPrompt<v1::Control::WithAsyncMethod_GetRigStatus<
                v1::Control::WithCallbackMethod_WatchSession<v1::Control::Service>>>>>>>>;

class ControlService final : public ControlServiceBase {
 public:
  // `rig` may be null (a server without a rig). All must outlive the service. `stopping` ends
  // WatchSession streams at shutdown; `program` ("brdfd", "brdf-archive") is WhoAmI's server.
  // `pump` runs WatchSession's streams.
  ControlService(SessionCatalogue& catalogue, RigPort* rig, const Authenticator& auth,
                 const StopSignal& stopping, StreamRegistry& streams, StreamPump& pump,
                 std::string program);

  // Adds the control plane's methods (the operator's verbs and GetRigStatus) to `loop`, which
  // then answers them with the methods below. Before the server is built.
  void ServeOn(ControlLoop& loop);

  // The rig's (control.cc).
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
  grpc::Status GetRigStatus(grpc::ServerContext* context, const v1::GetRigStatusRequest* request,
                            v1::RigStatus* response) override;
  // A snapshot, then every event until the session ends, the client cancels, or the server stops
  // (then UNAVAILABLE, after the events already queued were sent). On the stream pump
  // (watch_session.cc).
  grpc::ServerWriteReactor<v1::SessionEvent>* WatchSession(
      grpc::CallbackServerContext* context, const v1::WatchSessionRequest* request) override;
  // An adaptive session's stored rounds: the rig's store, or on brdf-archive the rounds the rigs
  // shipped (SessionCatalogue::AdaptiveRounds).
  grpc::Status ListAdaptiveRounds(grpc::ServerContext* context,
                                  const v1::ListAdaptiveRoundsRequest* request,
                                  v1::ListAdaptiveRoundsResponse* response) override;

  // The catalogue's (control_read.cc).
  grpc::Status GetSession(grpc::ServerContext* context, const v1::GetSessionRequest* request,
                          v1::Session* response) override;
  grpc::Status ListSessions(grpc::ServerContext* context, const v1::ListSessionsRequest* request,
                            v1::ListSessionsResponse* response) override;
  grpc::Status ListSessionEvents(grpc::ServerContext* context,
                                 const v1::ListSessionEventsRequest* request,
                                 v1::ListSessionEventsResponse* response) override;
  // The caller's token's name and role, and the program's name.
  grpc::Status WhoAmI(grpc::ServerContext* context, const v1::WhoAmIRequest* request,
                      v1::Caller* response) override;

 private:
  // FAILED_PRECONDITION for a rig's verb on a server without a rig (the token gate checked the
  // caller's role as on a rig), naming the rig of `session_id` when the catalogue knows it.
  grpc::Status NoRig(const char* method, const std::string& session_id);

  SessionCatalogue& catalogue_;
  RigPort* rig_;
  const Authenticator& auth_;
  const StopSignal& stopping_;
  StreamRegistry& streams_;
  StreamPump& pump_;
  std::string program_;
};

}  // namespace brdf::daemon
