// The CS-2000 protocol's pure side: commands, check codes, and every reply the driver parses.
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include "drivers/cs2000/protocol.h"

namespace brdf::drivers::cs2000 {
namespace {

using ::testing::HasSubstr;

TEST(Cs2000Commands, SpeedAndSyncCommandsCarryTheirValues) {
  EXPECT_EQ(*SpeedCommand(0, NdFilter::kAuto), "SPMS,0,2");
  EXPECT_EQ(*SpeedCommand(200, NdFilter::kOff), "SPMS,3,000200000,0");
  EXPECT_EQ(*SpeedCommand(120000, NdFilter::kOn), "SPMS,3,120000000,1");
  EXPECT_EQ(SpeedCommand(4, NdFilter::kAuto).status().code(), StatusCode::kInvalidArgument);
  EXPECT_EQ(*SyncCommand(false, 0), "SCMS,0");
  EXPECT_EQ(*SyncCommand(true, 100), "SCMS,1,10000");
  EXPECT_EQ(SyncCommand(true, 300).status().code(), StatusCode::kInvalidArgument);
  EXPECT_EQ(SpectralBlockCommand(3), "MEDR,1,0,3");
}

TEST(Cs2000CheckCodes, OkAndErrorRepliesParseAndErrorsSpeakTheMetersWords) {
  Result<Reply> ok = ParseReply("OK00,5\n", kMeasureCommand);
  ASSERT_TRUE(ok.ok());
  EXPECT_TRUE(ok->ok);
  EXPECT_EQ(ok->fields, std::vector<std::string>{"5"});
  Result<Reply> er = ParseReply("ER10\r\n", kMeasureCommand);
  ASSERT_TRUE(er.ok());
  EXPECT_FALSE(er->ok);
  EXPECT_EQ(er->code, 10);
  Result<Reply> refused = ParseOkReply("ER17\n", "SPMS,9,2");
  EXPECT_EQ(refused.status().device_code(), 17);
  EXPECT_THAT(refused.status().message(), HasSubstr("parameter error"));
  EXPECT_EQ(ParseReply("HELLO\n", "IDDR").status().code(), StatusCode::kProtocolError);
  EXPECT_EQ(PolicyCodeFor(10), 19);
  EXPECT_EQ(PolicyCodeFor(71), 7);
  EXPECT_EQ(PolicyCodeFor(2), 29);
  EXPECT_EQ(PolicyCodeFor(51), kFailPolicyCode);
  EXPECT_EQ(DescribeErrorCode(83), "ER83 (measurement angle abnormality)");
}

TEST(Cs2000Replies, IdentityByVariation) {
  EXPECT_EQ(ParseIdentityReply("OK00,CS-2000,1,20001234\n")->model, "CS-2000");
  EXPECT_EQ(ParseIdentityReply("OK00,CS-2000,2,20001234\n")->model, "CS-2000A");
  EXPECT_EQ(ParseIdentityReply("OK00,CS-3000,0,30000001\n")->model, "CS-3000");
  EXPECT_EQ(ParseIdentityReply("OK00,CS-2000,1,20001234\n")->serial_number, "20001234");
  EXPECT_EQ(ParseIdentityReply("OK00,CS-2000\n").status().code(), StatusCode::kProtocolError);
}

TEST(Cs2000Replies, MeasuringTimeAndSpectralBlocks) {
  EXPECT_EQ(*ParseMeasuringTime("OK00,12\n"), 12);
  EXPECT_EQ(ParseMeasuringTime("ER10\n").status().device_code(), 10);
  std::string block = "OK00";
  for (int i = 0; i < 101; ++i) block += "," + std::to_string(i) + ".0e-03";
  Result<std::vector<double>> last = ParseSpectralBlock(block + "\n", 4);
  ASSERT_TRUE(last.ok()) << last.status().ToString();
  EXPECT_EQ(last->size(), 101u);
  EXPECT_DOUBLE_EQ((*last)[100], 0.1);
  // 101 values are one too many for blocks 1–3.
  Result<std::vector<double>> wrong = ParseSpectralBlock(block + "\n", 1);
  EXPECT_EQ(wrong.status().code(), StatusCode::kProtocolError);
  EXPECT_THAT(wrong.status().message(), HasSubstr("101 values, not 100"));
  EXPECT_EQ(Grid(), (WavelengthGrid{380, 1, 401}));
}

}  // namespace
}  // namespace brdf::drivers::cs2000
