#include "daemon/api/data.h"

#include <string>
#include <utility>

#include "daemon/api/export_session.h"

namespace brdf::daemon {

DataService::DataService(SessionCatalogue& catalogue, const Authenticator& auth,
                         const StopSignal& stopping, StreamRegistry& streams, std::string program,
                         ExportInterpolants::Options kept)
    : catalogue_(catalogue),
      auth_(auth),
      stopping_(stopping),
      streams_(streams),
      program_(std::move(program)),
      export_interpolants_(streams.budget(), kept) {}

grpc::Status DataService::StreamReadings(grpc::ServerContext* context,
                                         const v1::StreamReadingsRequest* request,
                                         grpc::ServerWriter<v1::Reading>* writer) {
  return Serve(*context, *request, "StreamReadings",
               [&](StreamReadingsCall& call, const ReadingSource& source) {
                 return StreamSessionReadings(*context, *request, call, source, writer);
               });
}

grpc::Status DataService::StreamReadingPoints(grpc::ServerContext* context,
                                              const v1::StreamReadingsRequest* request,
                                              grpc::ServerWriter<v1::ReadingPoints>* writer) {
  return Serve(*context, *request, "StreamReadingPoints",
               [&](StreamReadingsCall& call, const ReadingSource& source) {
                 return StreamSessionReadingPoints(*context, *request, call, source, writer);
               });
}

grpc::Status DataService::Serve(grpc::ServerContext& context,
                                const v1::StreamReadingsRequest& request, const char* rpc,
                                const ReadingStreamBody& body) {
  StreamReadingsCall call;
  if (grpc::Status st = CheckStreamReadings(context, request, rpc, auth_, streams_, &call);
      !st.ok()) {
    return st;
  }
  storage::SessionReader& reader = catalogue_.reader();
  Result<storage::SessionRecord> session = reader.GetSession(call.session);
  if (!session.ok()) return ToGrpcStatus(session.status());

  const SessionFollow follow = catalogue_.Follow(call.session);
  ReadingSource source;
  source.reader = &reader;
  source.ended = follow.ended;
  source.wait = [&](std::int64_t last_id) { return follow.wait(stopping_, last_id); };
  source.recent = follow.recent;
  source.server = program_;
  // Labels and averaging are fixed at submission.
  source.extras = [&] {
    return ReadingExtrasOf(reader, call.session, catalogue_.Averages(call.session));
  };
  return body(call, source);
}

grpc::Status DataService::Export(grpc::ServerContext* context, const v1::ExportRequest* request,
                                 grpc::ServerWriter<v1::ExportChunk>* writer) {
  return ExportSession(*context, *request, *writer, auth_, streams_, stopping_, catalogue_.reader(),
                       export_loads_, export_interpolants_);
}

}  // namespace brdf::daemon
