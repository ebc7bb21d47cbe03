// Data.Export's data messages built as their wire bytes in place (issue 41, exports at the disk's
// speed). An ExportChunk holding ExportData {offset, content, part} is, on the wire, a few bytes
// of header, the content, and the part's field. ExportDataMessage takes the content into a buffer
// that has room for the header before it and the part after it, and hands the whole to gRPC as
// one slice: the export's bytes are copied once on their way to the socket (into this buffer),
// where a v1::ExportChunk would copy them twice (into its content field, then protobuf's
// serialization into gRPC's buffers). The bytes are those protobuf writes for the same message
// (export_wire_test.cc), so every client (brdfctl, Python, the web gateway) reads them unchanged.
#pragma once

#include <grpc/slice.h>
#include <grpcpp/support/byte_buffer.h>

#include <cstddef>
#include <cstdint>
#include <string>

#include "brdf/v1/brdf.pb.h"

namespace brdf::daemon {

class ExportDataMessage {
 public:
  // `part`: ExportData.part ("" for the file itself).
  explicit ExportDataMessage(std::string part = "") : part_(std::move(part)) {}
  ~ExportDataMessage();
  ExportDataMessage(const ExportDataMessage&) = delete;
  ExportDataMessage& operator=(const ExportDataMessage&) = delete;

  // Drops what is held and makes room for `capacity` bytes of content (one allocation).
  void Reset(std::size_t capacity);
  // Content bytes held, and room for them (0 before Reset and after Take).
  std::size_t size() const { return size_; }
  std::size_t capacity() const { return capacity_; }
  bool full() const { return capacity_ > 0 && size_ == capacity_; }
  // Copies up to capacity() − size() of the `n` bytes at `data`; returns how many it took.
  std::size_t Append(const char* data, std::size_t n);
  // The message: ExportChunk {data: {offset: `offset`, content: what was appended, part}} as
  // gRPC's buffer, which now owns the memory (freed once gRPC has sent it). This message holds
  // nothing afterwards (Reset before appending again).
  grpc::ByteBuffer Take(std::uint64_t offset);

 private:
  void Release();

  std::string part_;
  grpc_slice buffer_ = grpc_empty_slice();  // header room, content, part room
  std::size_t capacity_ = 0;
  std::size_t size_ = 0;
};

// Any other ExportChunk (progress, report) as gRPC's buffer, serialized by protobuf.
grpc::ByteBuffer SerializeExportChunk(const v1::ExportChunk& chunk);

}  // namespace brdf::daemon
