// brdfctl's end of Data.Export (tools/brdfctl/commands/export_stream.h): a data message read in
// place from the received slices, wherever they split it; any other layout of the same message,
// progress and the report parsed by protobuf; bytes that are no ExportChunk refused; and a file
// written from more pieces than one writev takes.
#include "tools/brdfctl/commands/export_stream.h"

#include <gtest/gtest.h>

#include <cstdio>
#include <fstream>
#include <iterator>
#include <string>
#include <vector>

namespace brdf::ctl {
namespace {

// `bytes` as a received buffer, cut into slices at `cuts`.
grpc::ByteBuffer Received(const std::string& bytes, std::vector<std::size_t> cuts) {
  std::vector<grpc::Slice> slices;
  std::size_t from = 0;
  cuts.push_back(bytes.size());
  for (std::size_t to : cuts) {
    slices.emplace_back(bytes.data() + from, to - from);
    from = to;
  }
  return grpc::ByteBuffer(slices.data(), slices.size());
}

std::string Joined(const std::vector<std::string_view>& pieces) {
  std::string out;
  for (std::string_view p : pieces) out.append(p);
  return out;
}

v1::ExportChunk DataChunk(std::uint64_t offset, const std::string& content,
                          const std::string& part) {
  v1::ExportChunk chunk;
  chunk.mutable_data()->set_offset(offset);
  chunk.mutable_data()->set_content(content);
  chunk.mutable_data()->set_part(part);
  return chunk;
}

TEST(ExportStreamTest, ADataMessageIsReadInPlaceWhereverTheSlicesSplitIt) {
  std::string content(3000, '\0');
  for (std::size_t i = 0; i < content.size(); ++i) content[i] = static_cast<char>(i * 7);
  const std::string wire = DataChunk(589032128, content, "u_measurement").SerializeAsString();
  for (std::vector<std::size_t> cuts : std::vector<std::vector<std::size_t>>{
           {}, {1}, {2, 3, 4, 5, 6, 7, 8, 9}, {10, 1500, 2999}, {wire.size() - 3}}) {
    grpc::ByteBuffer buffer = Received(wire, cuts);
    ExportMessage m;
    ASSERT_TRUE(ParseExportMessage(buffer, &m));
    EXPECT_TRUE(m.data);
    EXPECT_TRUE(m.owned.empty()) << "read in place, not copied by protobuf";
    EXPECT_EQ(m.offset, 589032128u);
    EXPECT_EQ(m.part, "u_measurement");
    EXPECT_EQ(m.content_size, content.size());
    EXPECT_EQ(Joined(m.content), content);
  }
}

TEST(ExportStreamTest, OtherLayoutsOfTheSameMessageAreParsedByProtobuf) {
  // part before content, and an unknown field: valid ExportChunk bytes brdfd does not write.
  std::string wire;
  const std::string inner = std::string(
      "\x1a\x01u\x12\x03"
      "abc\x08\x05\x20\x07",
      12);
  wire += '\x12';
  wire += static_cast<char>(inner.size());
  wire += inner;
  grpc::ByteBuffer buffer = Received(wire, {4});
  ExportMessage m;
  ASSERT_TRUE(ParseExportMessage(buffer, &m));
  EXPECT_TRUE(m.data);
  EXPECT_EQ(m.offset, 5u);
  EXPECT_EQ(m.part, "u");
  EXPECT_EQ(Joined(m.content), "abc");

  v1::ExportChunk progress;
  progress.mutable_progress()->set_stage("resampling");
  progress.mutable_progress()->set_fraction(0.5);
  grpc::ByteBuffer p = Received(progress.SerializeAsString(), {3});
  ASSERT_TRUE(ParseExportMessage(p, &m));
  EXPECT_FALSE(m.data);
  EXPECT_EQ(m.chunk.progress().stage(), "resampling");

  v1::ExportChunk report;
  report.mutable_report()->set_bytes(42);
  grpc::ByteBuffer r = Received(report.SerializeAsString(), {});
  ASSERT_TRUE(ParseExportMessage(r, &m));
  EXPECT_FALSE(m.data);
  EXPECT_EQ(m.chunk.report().bytes(), 42u);

  // An empty data message: no content.
  grpc::ByteBuffer empty = Received(DataChunk(0, "", "").SerializeAsString(), {});
  ASSERT_TRUE(ParseExportMessage(empty, &m));
  EXPECT_TRUE(m.data);
  EXPECT_EQ(m.content_size, 0u);
}

TEST(ExportStreamTest, BytesThatAreNoExportChunkAreRefused) {
  // A data field whose length runs past the end, then a truncated varint.
  for (const std::string& wire : {std::string("\x12\x7f\x12\x05"
                                              "ab",
                                              6),
                                  std::string("\x12\xff", 2)}) {
    grpc::ByteBuffer buffer = Received(wire, {});
    ExportMessage m;
    EXPECT_FALSE(ParseExportMessage(buffer, &m));
  }
}

TEST(ExportStreamTest, AFileIsWrittenFromMorePiecesThanOneWritevTakes) {
  std::string all;
  for (int i = 0; i < 5000; ++i) all += std::to_string(i) + ",";
  std::vector<std::string_view> pieces;
  for (std::size_t at = 0; at < all.size(); at += 3) {
    pieces.push_back(std::string_view(all).substr(at, 3));
  }
  const std::string path = ::testing::TempDir() + "export_stream_test.bin";
  ExportFile file;
  ASSERT_TRUE(file.Open(path));
  ASSERT_TRUE(file.Write(pieces));
  ASSERT_TRUE(file.Write({std::string_view("end")}));
  ASSERT_TRUE(file.Close());
  std::ifstream in(path, std::ios::binary);
  const std::string back((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  EXPECT_EQ(back, all + "end");
  std::remove(path.c_str());
  ExportFile missing;
  EXPECT_FALSE(missing.Open("/nonexistent-directory/x.npy"));
  EXPECT_FALSE(missing.Close());
}

}  // namespace
}  // namespace brdf::ctl
