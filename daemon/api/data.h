// The Data service (brdf.proto), once for brdfd and brdf-archive, over the server's
// SessionCatalogue: a session's readings streamed in id order a page at a time (memory bounded by
// one page whatever the session's size; stream_readings.h). With `follow` the stream stays open
// and sends readings as they arrive (the catalogue says how it learns of them: brdfd's commits,
// the archive's shipping), until the session ends, the client cancels, or the server stops. Its
// exports to files (Export) live in export.cc.
#pragma once

#include <grpcpp/support/byte_buffer.h>
#include <grpcpp/support/method_handler.h>
#include <grpcpp/support/sync_stream.h>

#include <string>

#include "brdf/v1/brdf.grpc.pb.h"
#include "daemon/api/common.h"
#include "daemon/api/export_cache.h"
#include "daemon/api/export_loads.h"
#include "daemon/api/export_session.h"
#include "daemon/api/session_catalogue.h"
#include "daemon/api/shared_extras.h"
#include "daemon/api/stream_pump.h"
#include "daemon/api/stream_readings.h"
#include "daemon/rpc/auth.h"
#include "daemon/rpc/method_index.h"
#include "daemon/rpc/stream_registry.h"

namespace brdf::daemon {

// Export on the synchronous pool as the generated service runs it, but writing gRPC's buffers
// (export_session.h: the data messages built as wire bytes, without protobuf's serialization
// copy). gRPC's split-streaming handler reads the one request and hands the stream to
// WireExport; the wire is unchanged (the same ExportChunk messages), so are the clients.
template <class Base>
class WithWireExport : public Base {
 public:
  using ExportStreamer = grpc::ServerSplitStreamer<v1::ExportRequest, grpc::ByteBuffer>;

  WithWireExport() {
    this->MarkMethodStreamed(
        MethodIndex(v1::Data::service_full_name(), "Export"),
        new grpc::internal::SplitServerStreamingHandler<v1::ExportRequest, grpc::ByteBuffer>(
            [this](grpc::ServerContext* context, ExportStreamer* streamer) {
              return this->WireExport(context, streamer);
            }));
  }
  // The generated handler, replaced by WireExport's.
  grpc::Status Export(grpc::ServerContext* /*context*/, const v1::ExportRequest* /*request*/,
                      grpc::ServerWriter<v1::ExportChunk>* /*writer*/) final {
    return grpc::Status(grpc::StatusCode::UNIMPLEMENTED, "Data.Export is served by WireExport");
  }
  virtual grpc::Status WireExport(grpc::ServerContext* context, ExportStreamer* streamer) = 0;
};

// StreamReadings on gRPC's callback API (the stream pump: a following stream that waits holds no
// thread); Export as above; the other methods on the synchronous pool.
using DataServiceBase =
    WithWireExport<v1::Data::WithCallbackMethod_StreamReadings<v1::Data::Service>>;

class DataService final : public DataServiceBase {
 public:
  // All must outlive the service. `program` ("brdfd", "brdf-archive") names the server in the
  // message that ends a following stream at shutdown; `pump` runs StreamReadings; `kept` bounds
  // the exports' kept interpolants ([export]).
  DataService(SessionCatalogue& catalogue, const Authenticator& auth, const StopSignal& stopping,
              StreamRegistry& streams, StreamPump& pump, std::string program,
              ExportInterpolants::Options kept = ExportInterpolants::Options());

  grpc::ServerWriteReactor<v1::Reading>* StreamReadings(
      grpc::CallbackServerContext* context, const v1::StreamReadingsRequest* request) override;
  // The same readings as columns of poses and directions, without spectra.
  grpc::Status StreamReadingPoints(grpc::ServerContext* context,
                                   const v1::StreamReadingsRequest* request,
                                   grpc::ServerWriter<v1::ReadingPoints>* writer) override;

  // A session exported to a file (readings CSV, grid .npy/CSV, MERL .binary, RGL .bsdf), streamed
  // as progress, the file's bytes in chunks, then the report (export_session.h). The same
  // session gives the same file from either server.
  grpc::Status WireExport(grpc::ServerContext* context, ExportStreamer* streamer) override;

 private:
  // Both readings streams (`rpc`: which one, for its errors): the request checked, the session
  // looked up, then `body` with the catalogue as the source.
  grpc::Status Serve(grpc::ServerContext& context, const v1::StreamReadingsRequest& request,
                     const char* rpc, const ReadingStreamBody& body);
  // What Serve does before `body`, into `opened` (which must not move afterwards).
  grpc::Status Open(grpc::ServerContextBase& context, const v1::StreamReadingsRequest& request,
                    const char* rpc, OpenedReadings* opened);

  SessionCatalogue& catalogue_;
  const Authenticator& auth_;
  const StopSignal& stopping_;
  StreamRegistry& streams_;
  StreamPump& pump_;
  std::string program_;
  SharedReadingExtras reading_extras_;      // the step labels the readings streams hold
  SharedSessionLoads export_loads_;         // the sessions the exports in flight hold
  ExportInterpolants export_interpolants_;  // their interpolants, kept per snapshot
};

}  // namespace brdf::daemon
