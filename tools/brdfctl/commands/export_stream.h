// brdfctl export's end of Data.Export (issue 41, exports at the disk's speed): the stream read as
// gRPC's buffers; a data message's content found in the received slices instead of copied out by
// protobuf's parser, and written to its file with writev straight from them. Progress, the
// report, and any data message not laid out as brdfd writes it (core/export/chunk_wire.h) are
// parsed by protobuf: the stream is the same ExportChunk messages whoever sent them.
#pragma once

#include <grpcpp/channel.h>
#include <grpcpp/client_context.h>
#include <grpcpp/impl/rpc_method.h>
#include <grpcpp/support/byte_buffer.h>
#include <grpcpp/support/slice.h>
#include <grpcpp/support/sync_stream.h>

#include <cstdint>
#include <memory>
#include <string>
#include <string_view>
#include <vector>

#include "brdf/v1/brdf.pb.h"

namespace brdf::ctl {

// One message of the stream as received.
struct ExportMessage {
  // A data message (ExportChunk.data): its offset and part, and its content as pieces of the
  // received message (kept alive by `slices`, or by `owned` when protobuf parsed it).
  bool data = false;
  std::uint64_t offset = 0;
  std::string part;
  std::vector<std::string_view> content;
  std::uint64_t content_size = 0;
  // Any other message (progress, report), parsed.
  v1::ExportChunk chunk;

  std::vector<grpc::Slice> slices;
  std::string owned;
};

// Reads `buffer` (one ExportChunk) into `out`; false when it is not one.
bool ParseExportMessage(grpc::ByteBuffer& buffer, ExportMessage* out);

// Data.Export called with `request` on `channel`, its messages read as gRPC's buffers.
class ExportStreamReader {
 public:
  ExportStreamReader(const std::shared_ptr<grpc::Channel>& channel, grpc::ClientContext* context,
                     const v1::ExportRequest& request);
  // The next message into `out`: false at the end of the stream (then Finish), or when a
  // message could not be parsed (then `malformed()`).
  bool Read(ExportMessage* out);
  bool malformed() const { return malformed_; }
  grpc::Status Finish() { return reader_->Finish(); }

 private:
  grpc::internal::RpcMethod method_;
  std::unique_ptr<grpc::ClientReader<grpc::ByteBuffer>> reader_;
  grpc::ByteBuffer buffer_;
  bool malformed_ = false;
};

// A file written from such pieces (writev, a thousand pieces a call).
class ExportFile {
 public:
  ExportFile() = default;
  ~ExportFile();
  ExportFile(const ExportFile&) = delete;
  ExportFile& operator=(const ExportFile&) = delete;

  // Creates or truncates `path`; false when it cannot.
  bool Open(const std::string& path);
  bool is_open() const { return fd_ >= 0; }
  // Appends the pieces; false (and the file failed) when the write fails.
  bool Write(const std::vector<std::string_view>& pieces);
  // Closes the file; false when it failed at any point (or never opened).
  bool Close();
  bool ok() const { return ok_; }

 private:
  int fd_ = -1;
  bool ok_ = false;
};

}  // namespace brdf::ctl
