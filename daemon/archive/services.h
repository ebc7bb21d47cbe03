// brdf-archive's Data service (archive/server.h), answered from the lab archive
// (storage/archive/reader.h) instead of a rig. Control is brdfd's own over the archive's catalogue
// (catalogue.h); Interpolation brdfd's own over an IndexCache that reads the archive.
//
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
