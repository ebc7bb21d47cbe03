// ExportDataMessage (export_wire.h): the wire form of ExportChunk {data: ExportData} laid out as
// core/export/chunk_wire.h describes it.
#include "daemon/api/export_wire.h"

#include <grpcpp/impl/codegen/proto_utils.h>
#include <grpcpp/support/slice.h>

#include <algorithm>
#include <cstring>

#include "core/export/chunk_wire.h"

namespace brdf::daemon {
namespace {

namespace wire = exports::chunk_wire;

// The layout's tags are the generated messages' field numbers (a renumbered proto fails here).
static_assert(wire::kChunkData == wire::Tag(v1::ExportChunk::kDataFieldNumber, wire::kLengthType));
static_assert(wire::kDataOffset ==
              wire::Tag(v1::ExportData::kOffsetFieldNumber, wire::kVarintType));
static_assert(wire::kDataContent ==
              wire::Tag(v1::ExportData::kContentFieldNumber, wire::kLengthType));
static_assert(wire::kDataPart == wire::Tag(v1::ExportData::kPartFieldNumber, wire::kLengthType));

// Room before the content: the chunk's tag and length, the offset's tag and value, the content's
// tag and length.
constexpr std::size_t kHeaderRoom = 3 * (1 + wire::kLongestVarint);

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
  const std::size_t trailer = 1 + wire::kLongestVarint + part_.size();
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
  const std::size_t offset_field = offset == 0 ? 0 : 1 + wire::VarintSize(offset);
  const std::size_t inner =
      offset_field + wire::BytesFieldSize(size_) + wire::BytesFieldSize(part_.size());
  // The header, written where it ends right before the content.
  std::uint8_t header[kHeaderRoom];
  std::uint8_t* end = header;
  *end++ = wire::kChunkData;
  end = wire::PutVarint(end, inner);
  if (offset != 0) {
    *end++ = wire::kDataOffset;
    end = wire::PutVarint(end, offset);
  }
  if (size_ > 0) {
    *end++ = wire::kDataContent;
    end = wire::PutVarint(end, size_);
  }
  const std::size_t header_size = static_cast<std::size_t>(end - header);
  std::uint8_t* const content = GRPC_SLICE_START_PTR(buffer_) + kHeaderRoom;
  std::memcpy(content - header_size, header, header_size);
  std::uint8_t* tail = content + size_;
  if (!part_.empty()) {
    *tail++ = wire::kDataPart;
    tail = wire::PutVarint(tail, part_.size());
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
