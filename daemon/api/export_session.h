// Data.Export's work (data.h), over any SessionCatalogue's reader (the rig's store, the archive):
// the caller authorized (kRead), a stream slot taken, the request checked, the session loaded
// through `reader` (or shared with the exports of it in flight: `loads`, export_loads.h) and the
// export's memory reserved (the stream registry's budget), the requested export computed by
// core/export, and its bytes streamed as progress, the file in chunks, then the report. The same
// session gives the same file from either server. Defined in export.cc.
//
// The messages are written as gRPC's own buffers (ExportWriter): the data messages are built as
// their wire bytes (export_wire.h) without protobuf's serialization copy; the wire is the same
// ExportChunk stream. data.h's WithWireExport serves the method so.
#pragma once

#include <grpcpp/support/byte_buffer.h>
#include <grpcpp/support/sync_stream.h>

#include "brdf/v1/brdf.grpc.pb.h"
#include "daemon/api/common.h"
#include "daemon/api/export_cache.h"
#include "daemon/api/export_loads.h"
#include "daemon/rpc/auth.h"
#include "daemon/rpc/stream_registry.h"
#include "storage/session_reader.h"

namespace brdf::daemon {

// Where an export writes its ExportChunk messages, serialized.
using ExportWriter = grpc::ServerReaderWriterInterface<grpc::ByteBuffer, v1::ExportRequest>;

grpc::Status ExportSession(grpc::ServerContext& context, const v1::ExportRequest& request,
                           ExportWriter& writer, const Authenticator& auth, StreamRegistry& streams,
                           const StopSignal& stopping, storage::SessionReader& reader,
                           SharedSessionLoads& loads, ExportInterpolants& kept);

}  // namespace brdf::daemon
