// The PR-670 protocol's pure side: commands, result codes, and every reply the driver parses.
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include "drivers/pr670/protocol.h"

namespace brdf::drivers::pr670 {
namespace {

using ::testing::HasSubstr;

TEST(Pr670Commands, SetupCommandsCarryTheirValuesAndRefuseOutOfRange) {
  EXPECT_EQ(*ExposureCommand(0), "SE0");
  EXPECT_EQ(*ExposureCommand(250), "SE250");
  EXPECT_EQ(ExposureCommand(1).status().code(), StatusCode::kInvalidArgument);
  EXPECT_EQ(ExposureCommand(30001).status().code(), StatusCode::kInvalidArgument);
  EXPECT_EQ(*AveragesCommand(3), "SN3");
  EXPECT_EQ(AveragesCommand(0).status().code(), StatusCode::kInvalidArgument);
  EXPECT_EQ(SyncCommand(true), "SS1");
  EXPECT_EQ(SyncCommand(false), "SS0");
}

TEST(Pr670ResultCodes, KnownCodesMapOntoThePolicyAndUnknownOnesFail) {
  EXPECT_EQ(PolicyCodeFor(0), 0);
  EXPECT_EQ(PolicyCodeFor(-8), 10);  // too dark → weak light
  EXPECT_EQ(PolicyCodeFor(-1), 7);   // sync failure → unable to sync
  EXPECT_EQ(PolicyCodeFor(-10), 7);
  EXPECT_EQ(PolicyCodeFor(-3), kUnknownPolicyCode);
  EXPECT_EQ(DescribeResultCode(-8), "-8 (too dark)");
  EXPECT_THAT(DescribeResultCode(-3), HasSubstr("does not know"));
}

TEST(Pr670ResultCodes, TheLeadingSignedIntegerIsTheCode) {
  EXPECT_EQ(*ParseResultCode("00000,0,1.0e+00\r\n", "M5"), 0);
  EXPECT_EQ(*ParseResultCode("-0008\r\n", "M5"), -8);
  EXPECT_EQ(*ParseResultCode("0000\r\n", "SE200"), 0);
  Result<int> bad = ParseResultCode("OK\r\n", "M5");
  EXPECT_EQ(bad.status().code(), StatusCode::kProtocolError);
  EXPECT_THAT(bad.status().message(), HasSubstr("M5"));
}

TEST(Pr670Replies, TextRepliesGiveTheirFieldAndErrorCodesTheirWords) {
  EXPECT_EQ(*ParseTextReply("00000,PR-670\r\n", kModelCommand), "PR-670");
  EXPECT_EQ(*ParseTextReply("00000,60925301  \r\n", kSerialNumberCommand), "60925301");
  Result<std::string> refused = ParseTextReply("-0010\r\n", kModelCommand);
  EXPECT_EQ(refused.status().code(), StatusCode::kDeviceError);
  EXPECT_EQ(refused.status().device_code(), -10);
  EXPECT_THAT(refused.status().message(), HasSubstr("sync failure"));
}

TEST(Pr670Replies, TheLayoutIsTheGrid) {
  EXPECT_EQ(*ParseLayoutReply("00000,201,0.00,380,780,2,256,7,247\r\n"),
            (WavelengthGrid{380, 2, 201}));
  EXPECT_EQ(*ParseLayoutReply("00000,101,8.00,380,780,4\r\n"), WavelengthGrid::Pr650());
  EXPECT_EQ(ParseLayoutReply("00000,201,0.00,380,700,2\r\n").status().code(),
            StatusCode::kProtocolError);  // first + step × (points − 1) ≠ last
}

std::string Report(int bands, double step, int first = 380) {
  std::string r = "00000,0,5.500e+02,1.827e-01,5.147e+01\r\n";
  for (int i = 0; i < bands; ++i) {
    r += std::to_string(first + static_cast<int>(step * i)) + "," +
         std::to_string(0.001 * (i + 1)) + "\r\n";
  }
  return r;
}

TEST(Pr670Replies, ReportFiveIsTheHeaderAndOneLinePerBand) {
  Result<SpectrumReply> r = ParseSpectrumReply(Report(201, 2), WavelengthGrid{380, 2, 201}, "M5");
  ASSERT_TRUE(r.ok()) << r.status().ToString();
  EXPECT_EQ(r->header.result_code, 0);
  EXPECT_EQ(r->header.units_code, 0);
  EXPECT_DOUBLE_EQ(r->header.integrated, 0.1827);
  ASSERT_EQ(r->values.size(), 201u);
  EXPECT_DOUBLE_EQ(r->values[0], 0.001);
  EXPECT_DOUBLE_EQ(r->values[200], 0.201);
}

TEST(Pr670Replies, AReportOfAnotherGridOrWithABadLineIsRefused) {
  EXPECT_EQ(ParseSpectrumReply(Report(101, 4), WavelengthGrid{380, 2, 201}, "M5").status().code(),
            StatusCode::kProtocolError);
  std::string broken = Report(201, 2);
  broken.replace(broken.find("384,"), 4, "384;");
  Result<SpectrumReply> r = ParseSpectrumReply(broken, std::nullopt, "M5");
  EXPECT_EQ(r.status().code(), StatusCode::kProtocolError);
  EXPECT_THAT(r.status().message(), HasSubstr("line 4"));
  EXPECT_EQ(ParseSpectrumReply("-0008\r\n", std::nullopt, "M5").status().device_code(), -8);
}

}  // namespace
}  // namespace brdf::drivers::pr670
