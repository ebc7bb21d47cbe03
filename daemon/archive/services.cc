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

namespace brdf::daemon {
namespace {

// How often StreamReadings with follow looks for readings newly shipped to the archive.
constexpr std::chrono::milliseconds kArchivePollInterval{1000};

}  // namespace

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

}  // namespace brdf::daemon
