// core/export/chunk_wire.h: the varints both ends of the export's bytes path write and read
// (protobuf's own bytes for whole messages are checked by export_wire_test and export_stream_test).
#include "core/export/chunk_wire.h"

#include <gtest/gtest.h>

#include <cstdint>
#include <limits>
#include <vector>

namespace brdf::exports::chunk_wire {
namespace {

// Reads from `bytes` as a message's bytes would arrive.
struct ByteSource {
  const std::vector<std::uint8_t>& bytes;
  std::size_t at = 0;
  bool operator()(std::uint8_t* b) {
    if (at == bytes.size()) return false;
    *b = bytes[at++];
    return true;
  }
};

std::vector<std::uint8_t> Encode(std::uint64_t v) {
  std::vector<std::uint8_t> out(kLongestVarint);
  out.resize(static_cast<std::size_t>(PutVarint(out.data(), v) - out.data()));
  return out;
}

TEST(ChunkWireTest, TagsAreProtobufsForTheFieldNumbers) {
  EXPECT_EQ(kChunkData, 0x12);
  EXPECT_EQ(kDataOffset, 0x08);
  EXPECT_EQ(kDataContent, 0x12);
  EXPECT_EQ(kDataPart, 0x1a);
}

TEST(ChunkWireTest, VarintsRoundTripAtEveryLengthBoundary) {
  for (unsigned bits = 0; bits <= 64; ++bits) {
    for (std::uint64_t v : {bits == 0 ? 0 : (std::uint64_t{1} << (bits - 1)),
                            bits == 64 ? std::numeric_limits<std::uint64_t>::max()
                                       : (std::uint64_t{1} << bits) - 1}) {
      const std::vector<std::uint8_t> bytes = Encode(v);
      EXPECT_EQ(bytes.size(), VarintSize(v)) << v;
      ByteSource in{bytes};
      std::uint64_t back = 0;
      ASSERT_TRUE(GetVarint(in, &back)) << v;
      EXPECT_EQ(back, v);
      EXPECT_EQ(in.at, bytes.size()) << "reads exactly its own bytes";
    }
  }
  EXPECT_EQ(Encode(300), (std::vector<std::uint8_t>{0xac, 0x02}));  // protobuf's guide's example
}

TEST(ChunkWireTest, TruncatedOrOverlongVarintsAreRefused) {
  const std::vector<std::uint8_t> cut = {0xac};
  ByteSource short_in{cut};
  std::uint64_t v = 0;
  EXPECT_FALSE(GetVarint(short_in, &v));

  const std::vector<std::uint8_t> eleven(11, 0x80);
  ByteSource long_in{eleven};
  EXPECT_FALSE(GetVarint(long_in, &v));
  EXPECT_EQ(long_in.at, kLongestVarint) << "stops after the longest a uint64 can take";
}

TEST(ChunkWireTest, EmptyBytesFieldsAreLeftOut) {
  EXPECT_EQ(BytesFieldSize(0), 0u);
  EXPECT_EQ(BytesFieldSize(5), 1u + 1u + 5u);
  EXPECT_EQ(BytesFieldSize(200), 1u + 2u + 200u);
}

}  // namespace
}  // namespace brdf::exports::chunk_wire
