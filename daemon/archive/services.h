// brdf-archive's own services (archive_server.h): the read side of the Control and Data services
// answered from the lab archive (storage/archive/reader.h) instead of a rig. Interpolation is the
// daemon's own InterpolationService over an IndexCache that reads the archive.
//
//   Control  GetSession, ListSessions (across rigs, with the catalogue filters of
//            ListSessionsRequest and paging, newest first), ListSessionEvents (the history the
//            rig shipped; the same code as brdfd's, service_common.h). The rig's verbs (SubmitPlan,
//            ValidatePlan, Start/Pause/Resume/Abort, AnswerPrompt), GetRigStatus and WatchSession
//            answer FAILED_PRECONDITION saying that this is the archive and naming the rig's brdfd
//            as the place to ask (the session's rig when the request names a session).
//   Data     StreamReadings as on the rig (with follow: the archive is polled while the session
//            is not finished); Export as on the rig (export_session.h: the same code over the
//            archive's records, so the same file, byte for byte, but for the session id the
//            readings CSV's first line and the file name carry).
//
// Session ids are the archive's (sessions.archive_id), not the rig's: the same session has
// another id here than on its rig; its uuid and rig name are the same everywhere. A Session here
// carries what the archive holds: no plan summary or ETA (they need the rig's description),
// last_quality_code −1, no live prompt or fault.
#pragma once

#include <memory>

#include "brdf/v1/brdf.grpc.pb.h"
#include "daemon/api/common.h"
#include "daemon/api/stream_readings.h"
#include "daemon/rpc/auth.h"
#include "daemon/rpc/stream_registry.h"
#include "storage/archive/reader.h"

namespace brdf::daemon {

// The API's Session for an archived record: with its plan when `with_plan`, progress from
// `steps` when given (else only the step counts).
v1::Session ArchivedSession(const storage::SessionRecord& record,
                            const std::vector<storage::StepRecord>* steps, bool with_plan);

class ArchiveControlService final : public v1::Control::Service {
 public:
  // All must outlive the service.
  ArchiveControlService(std::shared_ptr<storage::ArchiveReader> archive, const Authenticator& auth);

  grpc::Status GetSession(grpc::ServerContext* context, const v1::GetSessionRequest* request,
                          v1::Session* response) override;
  grpc::Status ListSessions(grpc::ServerContext* context, const v1::ListSessionsRequest* request,
                            v1::ListSessionsResponse* response) override;
  grpc::Status ListSessionEvents(grpc::ServerContext* context,
                                 const v1::ListSessionEventsRequest* request,
                                 v1::ListSessionEventsResponse* response) override;

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
  grpc::Status WatchSession(grpc::ServerContext* context, const v1::WatchSessionRequest* request,
                            grpc::ServerWriter<v1::SessionEvent>* writer) override;
  // The caller's token's name and role, and "brdf-archive".
  grpc::Status WhoAmI(grpc::ServerContext* context, const v1::WhoAmIRequest* request,
                      v1::Caller* response) override;

 private:
  // FAILED_PRECONDITION for a rig's verb (the token gate checked the caller's role as on a rig).
  grpc::Status NotHere(const char* method, const std::string& session_id);

  std::shared_ptr<storage::ArchiveReader> archive_;
  const Authenticator& auth_;
};

class ArchiveDataService final : public v1::Data::Service {
 public:
  ArchiveDataService(std::shared_ptr<storage::ArchiveReader> archive, const Authenticator& auth,
                     const StopSignal& stopping, StreamRegistry& streams);

  grpc::Status StreamReadings(grpc::ServerContext* context,
                              const v1::StreamReadingsRequest* request,
                              grpc::ServerWriter<v1::Reading>* writer) override;
  grpc::Status StreamReadingPoints(grpc::ServerContext* context,
                                   const v1::StreamReadingsRequest* request,
                                   grpc::ServerWriter<v1::ReadingPoints>* writer) override;
  grpc::Status Export(grpc::ServerContext* context, const v1::ExportRequest* request,
                      grpc::ServerWriter<v1::ExportChunk>* writer) override;

 private:
  // Both readings streams (`rpc`: which one, for its errors): the request checked, the session
  // looked up, then `body` with the archive as the source (polled for newly shipped readings).
  grpc::Status Serve(grpc::ServerContext& context, const v1::StreamReadingsRequest& request,
                     const char* rpc, const ReadingStreamBody& body);
  std::shared_ptr<storage::ArchiveReader> archive_;
  const Authenticator& auth_;
  const StopSignal& stopping_;
  StreamRegistry& streams_;
};

}  // namespace brdf::daemon
