#include "daemon/api/data.h"

#include <string>
#include <utility>

#include "daemon/api/export_session.h"

namespace brdf::daemon {

DataService::DataService(SessionCatalogue& catalogue, const Authenticator& auth,
                         const StopSignal& stopping, StreamRegistry& streams, StreamPump& pump,
                         std::string program, ExportInterpolants::Options kept)
    : catalogue_(catalogue),
      auth_(auth),
      stopping_(stopping),
      streams_(streams),
      pump_(pump),
      program_(std::move(program)),
      export_interpolants_(streams.budget(), kept) {}

grpc::ServerWriteReactor<v1::Reading>* DataService::StreamReadings(
    grpc::CallbackServerContext* context, const v1::StreamReadingsRequest* request) {
  return new PumpedStream<v1::Reading>(
      pump_,
      StreamReadingsBody(*context, *request, stopping_,
                         [this, context, request](OpenedReadings* opened) {
                           return Open(*context, *request, "StreamReadings", opened);
                         }),
      kStreamIdleWait);
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
  OpenedReadings opened;
  if (grpc::Status st = Open(context, request, rpc, &opened); !st.ok()) return st;
  return body(opened.call, opened.source);
}

grpc::Status DataService::Open(grpc::ServerContextBase& context,
                               const v1::StreamReadingsRequest& request, const char* rpc,
                               OpenedReadings* opened) {
  StreamReadingsCall& call = opened->call;
  if (grpc::Status st = CheckStreamReadings(context, request, rpc, auth_, streams_, &call);
      !st.ok()) {
    return st;
  }
  storage::SessionReader& reader = catalogue_.reader();
  Result<storage::SessionRecord> session = reader.GetSession(call.session);
  if (!session.ok()) return ToGrpcStatus(session.status());

  opened->follow = catalogue_.Follow(call.session);
  const SessionFollow& follow = opened->follow;
  ReadingSource& source = opened->source;
  source.reader = &reader;
  source.ended = follow.ended;
  source.wait = [this, &follow](std::int64_t last_id) { return follow.wait(stopping_, last_id); };
  source.recent = follow.recent;
  source.notify = follow.notify;
  source.server = program_;
  // Labels and averaging are fixed at submission.
  const std::int64_t id = call.session;
  source.extras = [this, &reader, id] {
    return reading_extras_.Get(
        id, [&] { return ReadingExtrasOf(reader, id, catalogue_.Averages(id)); });
  };
  return grpc::Status::OK;
}

grpc::Status DataService::WireExport(grpc::ServerContext* context, ExportStreamer* streamer) {
  v1::ExportRequest request;
  if (!streamer->Read(&request)) {
    return grpc::Status(grpc::StatusCode::INTERNAL,
                        "Export: the request could not be read; send an ExportRequest");
  }
  return ExportSession(*context, request, *streamer, auth_, streams_, stopping_,
                       catalogue_.reader(), export_loads_, export_interpolants_);
}

}  // namespace brdf::daemon
