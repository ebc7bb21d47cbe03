// InterpolateBatch's request as the batch holds it (issue 40's memory goal). gRPC's synchronous
// server parses a request before its handler runs, and a parsed batch of 100,000 directions is
// ~13 MB of small messages (a DirectionQuery and its IsoDirection each, ~130 bytes with malloc's
// overhead, for 24 bytes of angles; 2.4 MB on the wire), held while the batch waits for a work
// permit and while it waits for its client. So InterpolateBatch is served as gRPC's split
// streaming handler (WithWireBatchRequest): the handler takes its work permit first, then reads
// the request's wire bytes, parses them on an arena of blocks mapped for that parse alone, and
// keeps the directions packed (25 bytes each, 33 with four-angle ones) and the other fields as a
// message. The wire is unchanged (the same InterpolateBatchRequest and InterpolateBatchChunk), so
// are the clients and the errors (a request gRPC cannot parse: INTERNAL; one over the receive
// limit: RESOURCE_EXHAUSTED from the transport). Until the handler reads it, a request stays in
// gRPC's transport, within HTTP/2's flow-control window.
#pragma once

#include <grpcpp/support/byte_buffer.h>
#include <grpcpp/support/method_handler.h>
#include <grpcpp/support/sync_stream.h>

#include <array>
#include <cstddef>
#include <cstdint>
#include <vector>

#include "brdf/v1/brdf.grpc.pb.h"
#include "daemon/rpc/method_index.h"

namespace brdf::daemon {

// One DirectionQuery: its form (kIso, kFour, or DIRECTION_NOT_SET when none was set) and its
// angles in the proto's order (iso: θi, θo, φ, 0; four: θi, φi, θo, φo), degrees as sent.
struct QueryAngles {
  v1::DirectionQuery::DirectionCase form = v1::DirectionQuery::DIRECTION_NOT_SET;
  std::array<double, 4> angles{};
};

QueryAngles AnglesOf(const v1::DirectionQuery& query);
// The query as it was sent (AnglesOf's inverse).
void ToQuery(const QueryAngles& angles, v1::DirectionQuery* query);

// A batch's directions packed: each one's form a byte, its angles a row of 3 doubles while every
// direction is isotropic (25 bytes a direction), of 4 when one is not (33 bytes).
class PackedDirections {
 public:
  void Assign(const google::protobuf::RepeatedPtrField<v1::DirectionQuery>& queries);
  std::size_t size() const { return forms_.size(); }
  QueryAngles operator[](std::size_t i) const;
  std::size_t Bytes() const { return forms_.capacity() + angles_.capacity() * sizeof(double); }

 private:
  std::size_t stride_ = 3;           // angles per direction
  std::vector<std::uint8_t> forms_;  // DirectionCase
  std::vector<double> angles_;
};

// A parsed InterpolateBatchRequest: every field but `directions` in `settings`, the directions
// packed in `directions`.
struct BatchRequest {
  v1::InterpolateBatchRequest settings;
  PackedDirections directions;

  // What it holds, bytes (for the memory budget).
  std::size_t Bytes() const { return settings.ByteSizeLong() + directions.Bytes(); }
};

using BatchStreamer = grpc::ServerSplitStreamer<grpc::ByteBuffer, v1::InterpolateBatchChunk>;

// The call's one request read from the transport and parsed into *out: INTERNAL when it cannot be
// read or parsed (as gRPC's own handler answers a request it cannot parse). A request over the
// server's receive limit never gets here: gRPC ends the call with RESOURCE_EXHAUSTED.
grpc::Status ReadBatchRequest(BatchStreamer& streamer, BatchRequest* out);

// InterpolateBatch on the synchronous pool, its request read by the handler (WireBatch) rather
// than parsed before it runs.
template <class Base>
class WithWireBatchRequest : public Base {
 public:
  WithWireBatchRequest() {
    this->MarkMethodStreamed(
        MethodIndex(v1::Interpolation::service_full_name(), "InterpolateBatch"),
        new grpc::internal::SplitServerStreamingHandler<grpc::ByteBuffer,
                                                        v1::InterpolateBatchChunk>(
            [this](grpc::ServerContext* context, BatchStreamer* streamer) {
              return this->WireBatch(context, streamer);
            }));
  }
  // The generated handler, replaced by WireBatch's.
  grpc::Status InterpolateBatch(grpc::ServerContext* /*context*/,
                                const v1::InterpolateBatchRequest* /*request*/,
                                grpc::ServerWriter<v1::InterpolateBatchChunk>* /*writer*/) final {
    return grpc::Status(grpc::StatusCode::UNIMPLEMENTED,
                        "Interpolation.InterpolateBatch is served by WireBatch");
  }
  virtual grpc::Status WireBatch(grpc::ServerContext* context, BatchStreamer* streamer) = 0;
};

}  // namespace brdf::daemon
