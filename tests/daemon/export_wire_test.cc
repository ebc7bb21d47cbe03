// ExportDataMessage (daemon/api/export_wire.h): the data messages brdfd builds as wire bytes are
// the bytes protobuf writes for the same ExportChunk, and parse back to it, whatever the offset,
// content size (varint lengths of 1 to 3 bytes) and part.
#include "daemon/api/export_wire.h"

#include <grpcpp/support/slice.h>
#include <gtest/gtest.h>

#include <string>
#include <vector>

namespace brdf::daemon {
namespace {

std::string Bytes(const grpc::ByteBuffer& buffer) {
  std::vector<grpc::Slice> slices;
  EXPECT_TRUE(buffer.Dump(&slices).ok());
  std::string out;
  for (const grpc::Slice& s : slices)
    out.append(reinterpret_cast<const char*>(s.begin()), s.size());
  return out;
}

std::string Content(std::size_t n) {
  std::string s(n, '\0');
  for (std::size_t i = 0; i < n; ++i) s[i] = static_cast<char>(i * 131 + 7);
  return s;
}

TEST(ExportWireTest, DataMessagesAreProtobufsBytes) {
  for (const std::string part : {"", "u", "u_measurement"}) {
    for (std::uint64_t offset : {0ULL, 1ULL, 127ULL, 128ULL, 589032128ULL, 1ULL << 40}) {
      for (std::size_t n : {0, 1, 127, 128, 16383, 16384, 70000}) {
        const std::string content = Content(n);
        ExportDataMessage message(part);
        message.Reset(n);
        // Appended in two pieces, the second more than the room left: only the room is taken.
        const std::size_t half = n / 2;
        EXPECT_EQ(message.Append(content.data(), half), half);
        EXPECT_EQ(message.Append(content.data() + half, n - half), n - half);
        EXPECT_EQ(message.Append("x", 1), 0u);
        EXPECT_EQ(message.full(), n > 0);

        v1::ExportChunk expected;
        expected.mutable_data()->set_offset(offset);
        expected.mutable_data()->set_content(content);
        expected.mutable_data()->set_part(part);
        const std::string wire = Bytes(message.Take(offset));
        EXPECT_EQ(wire, expected.SerializeAsString())
            << "part '" << part << "' offset " << offset << " bytes " << n;
        v1::ExportChunk parsed;
        ASSERT_TRUE(parsed.ParseFromString(wire));
        EXPECT_EQ(parsed.data().content(), content);
        EXPECT_EQ(parsed.data().offset(), offset);
        EXPECT_EQ(parsed.data().part(), part);
        EXPECT_EQ(message.capacity(), 0u);
        EXPECT_EQ(message.size(), 0u);
      }
    }
  }
}

TEST(ExportWireTest, AMessageCanBeFilledAgainAfterItWasTaken) {
  ExportDataMessage message;
  message.Reset(4);
  EXPECT_EQ(message.Append("abcdef", 6), 4u);
  const std::string first = Bytes(message.Take(0));
  message.Reset(2);
  EXPECT_EQ(message.Append("ef", 2), 2u);
  v1::ExportChunk parsed;
  ASSERT_TRUE(parsed.ParseFromString(Bytes(message.Take(4))));
  EXPECT_EQ(parsed.data().content(), "ef");
  EXPECT_EQ(parsed.data().offset(), 4u);
  ASSERT_TRUE(parsed.ParseFromString(first));
  EXPECT_EQ(parsed.data().content(), "abcd");
}

TEST(ExportWireTest, OtherMessagesAreSerializedByProtobuf) {
  v1::ExportChunk progress;
  progress.mutable_progress()->set_stage("resampling");
  progress.mutable_progress()->set_fraction(0.25);
  EXPECT_EQ(Bytes(SerializeExportChunk(progress)), progress.SerializeAsString());
  v1::ExportChunk report;
  report.mutable_report()->set_file_name("session-1-grid.npy");
  report.mutable_report()->set_bytes(589032128);
  report.mutable_report()->set_description_json(Content(5000));
  EXPECT_EQ(Bytes(SerializeExportChunk(report)), report.SerializeAsString());
}

}  // namespace
}  // namespace brdf::daemon
