// The wire layout of an export's data message, ExportChunk {data: ExportData} (brdf.proto), as
// protobuf writes it: fields in number order, zero and empty fields left out, lengths and
// integers as base-128 varints (protobuf's encoding guide, "Base 128 Varints" and "Length-
// Delimited Records"):
//   0x12 varint(len) ExportData   ExportChunk.data, field 2, length-delimited
//     0x08 varint(offset)         ExportData.offset, field 1 (when not 0)
//     0x12 varint(n) content      ExportData.content, field 2 (when not empty)
//     0x1a varint(m) part         ExportData.part, field 3 (when not empty)
// One description for both ends that skip protobuf's copies: brdfd's writer
// (daemon/api/export_wire.h, which checks these tags against the generated field numbers) and
// brdfctl's reader (tools/brdfctl/commands/export_stream.h). Pure: no I/O, no protobuf.
#pragma once

#include <cstddef>
#include <cstdint>

namespace brdf::exports::chunk_wire {

// A field's tag: its number shifted left by 3, with the wire type (0 varint, 2 length-delimited).
constexpr std::uint8_t Tag(unsigned field, unsigned wire_type) {
  return static_cast<std::uint8_t>(field << 3 | wire_type);
}
inline constexpr unsigned kVarintType = 0;
inline constexpr unsigned kLengthType = 2;

inline constexpr std::uint8_t kChunkData = Tag(2, kLengthType);    // ExportChunk.data
inline constexpr std::uint8_t kDataOffset = Tag(1, kVarintType);   // ExportData.offset
inline constexpr std::uint8_t kDataContent = Tag(2, kLengthType);  // ExportData.content
inline constexpr std::uint8_t kDataPart = Tag(3, kLengthType);     // ExportData.part

inline constexpr std::size_t kLongestVarint = 10;  // a uint64: 64 bits, 7 a byte

constexpr std::size_t VarintSize(std::uint64_t v) {
  std::size_t n = 1;
  while (v >= 0x80) {
    v >>= 7;
    ++n;
  }
  return n;
}

// Writes `v` at `at` (room for VarintSize(v) bytes); returns the byte after it.
inline std::uint8_t* PutVarint(std::uint8_t* at, std::uint64_t v) {
  while (v >= 0x80) {
    *at++ = static_cast<std::uint8_t>(v | 0x80);
    v >>= 7;
  }
  *at++ = static_cast<std::uint8_t>(v);
  return at;
}

// Reads a varint from `next_byte` (callable as bool(std::uint8_t*), false when the bytes end).
// False when they end inside it or it runs past kLongestVarint bytes.
template <class NextByte>
bool GetVarint(NextByte&& next_byte, std::uint64_t* v) {
  *v = 0;
  for (unsigned shift = 0; shift < 7 * kLongestVarint; shift += 7) {
    std::uint8_t b = 0;
    if (!next_byte(&b)) return false;
    *v |= static_cast<std::uint64_t>(b & 0x7f) << shift;
    if ((b & 0x80) == 0) return true;
  }
  return false;
}

// A length-delimited field's size with its tag: 0 when empty (left out).
constexpr std::size_t BytesFieldSize(std::size_t n) {
  return n == 0 ? 0 : 1 + VarintSize(n) + n;
}

}  // namespace brdf::exports::chunk_wire
