// ExportDataMessage (export_wire.h): the wire form of ExportChunk {data: ExportData}, as protobuf
// writes it (fields in number order, zero and empty fields left out, lengths as varints):
//   0x12 len(ExportData)          ExportChunk.data, field 2, length-delimited
//     0x08 varint(offset)         ExportData.offset, field 1 (when not 0)
//     0x12 varint(n) content      ExportData.content, field 2 (when not empty)
//     0x1a varint(m) part         ExportData.part, field 3 (when not empty)
#include "daemon/api/export_wire.h"

#include <grpcpp/impl/codegen/proto_utils.h>
#include <grpcpp/support/slice.h>

#include <algorithm>
#include <cstring>

namespace brdf::daemon {
namespace {

constexpr std::uint8_t kChunkData = 0x12;    // ExportChunk.data: field 2, wire type 2
constexpr std::uint8_t kDataOffset = 0x08;   // ExportData.offset: field 1, wire type 0
constexpr std::uint8_t kDataContent = 0x12;  // ExportData.content: field 2, wire type 2
constexpr std::uint8_t kDataPart = 0x1a;     // ExportData.part: field 3, wire type 2
constexpr std::size_t kLongestVarint = 10;   // a uint64
// Room before the content: the chunk's tag and length, the offset's tag and value, the content's
// tag and length.
constexpr std::size_t kHeaderRoom = 3 * (1 + kLongestVarint);

std::size_t VarintSize(std::uint64_t v) {
  std::size_t n = 1;
  while (v >= 0x80) {
    v >>= 7;
    ++n;
  }
  return n;
}

std::uint8_t* PutVarint(std::uint8_t* at, std::uint64_t v) {
  while (v >= 0x80) {
    *at++ = static_cast<std::uint8_t>(v | 0x80);
    v >>= 7;
  }
  *at++ = static_cast<std::uint8_t>(v);
  return at;
}

// A length-delimited field's size on the wire, with its tag: 0 when empty (left out).
std::size_t BytesFieldSize(std::size_t n) {
  return n == 0 ? 0 : 1 + VarintSize(n) + n;
}

}  // namespace

ExportDataMessage::~ExportDataMessage() {
  Release();
}

void ExportDataMessage::Release() {
  grpc_slice_unref(buffer_);
  buffer_ = grpc_empty_slice();
  capacity_ = 0;
  size_ = 0;
}

void ExportDataMessage::Reset(std::size_t capacity) {
  Release();
  const std::size_t trailer = 1 + kLongestVarint + part_.size();
  buffer_ = grpc_slice_malloc(kHeaderRoom + capacity + trailer);
  capacity_ = capacity;
}

std::size_t ExportDataMessage::Append(const char* data, std::size_t n) {
  const std::size_t take = std::min(n, capacity_ - size_);
  if (take > 0) std::memcpy(GRPC_SLICE_START_PTR(buffer_) + kHeaderRoom + size_, data, take);
  size_ += take;
  return take;
}

grpc::ByteBuffer ExportDataMessage::Take(std::uint64_t offset) {
  if (GRPC_SLICE_LENGTH(buffer_) == 0) Reset(0);
  const std::size_t offset_field = offset == 0 ? 0 : 1 + VarintSize(offset);
  const std::size_t inner = offset_field + BytesFieldSize(size_) + BytesFieldSize(part_.size());
  // The header, written where it ends right before the content.
  std::uint8_t header[kHeaderRoom];
  std::uint8_t* end = header;
  *end++ = kChunkData;
  end = PutVarint(end, inner);
  if (offset != 0) {
    *end++ = kDataOffset;
    end = PutVarint(end, offset);
  }
  if (size_ > 0) {
    *end++ = kDataContent;
    end = PutVarint(end, size_);
  }
  const std::size_t header_size = static_cast<std::size_t>(end - header);
  std::uint8_t* const content = GRPC_SLICE_START_PTR(buffer_) + kHeaderRoom;
  std::memcpy(content - header_size, header, header_size);
  std::uint8_t* tail = content + size_;
  if (!part_.empty()) {
    *tail++ = kDataPart;
    tail = PutVarint(tail, part_.size());
    tail = std::copy(part_.begin(), part_.end(), tail);
  }
  const std::size_t first = kHeaderRoom - header_size;
  grpc::Slice message(
      grpc_slice_sub(buffer_, first,
                     static_cast<std::size_t>(tail - GRPC_SLICE_START_PTR(buffer_))),
      grpc::Slice::STEAL_REF);
  Release();
  return grpc::ByteBuffer(&message, 1);
}

grpc::ByteBuffer SerializeExportChunk(const v1::ExportChunk& chunk) {
  grpc::ByteBuffer out;
  bool own = false;
  (void)grpc::SerializationTraits<v1::ExportChunk>::Serialize(chunk, &out, &own);
  return out;
}

}  // namespace brdf::daemon
