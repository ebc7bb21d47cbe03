// The PR-650 reply parsers and command formatting, line by line, including malformed replies.
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <cstdio>
#include <string>

#include "drivers/pr650/protocol.h"
#include "drivers/serial/reply_lines.h"

namespace brdf::drivers::pr650 {
namespace {

using serial::CountCompleteLines;
using serial::EndsWithLineEnd;
using serial::Printable;
using serial::SplitReplyLines;

using ::testing::ElementsAre;
using ::testing::HasSubstr;

// A D5 report built line by line, the way the meter sends it.
std::string SpectrumReport(const std::string& header, const std::string& integrated, int bands,
                           const std::string& eol = "\r\n", int first_nm = 380, int step_nm = 4) {
  std::string out = header + eol + integrated + eol;
  for (int i = 0; i < bands; ++i) {
    char line[32];
    std::snprintf(line, sizeof line, "%04d.,%.3E", first_nm + step_nm * i, 1e-3 * (i + 1));
    out += line + eol;
  }
  return out;
}

// ---- framing helpers ---------------------------------------------------------------------------

TEST(SplitReplyLines, AcceptsCrLfLfAndBareCr) {
  EXPECT_THAT(SplitReplyLines("a\r\nb\nc\rd"), ElementsAre("a", "b", "c", "d"));
  EXPECT_THAT(SplitReplyLines("000\r\n"), ElementsAre("000"));
  EXPECT_THAT(SplitReplyLines("\r\n\r\nx\n\n"), ElementsAre("x"));
  EXPECT_TRUE(SplitReplyLines("").empty());
}

TEST(CountCompleteLines, CountsOnlyTerminatedLines) {
  EXPECT_EQ(CountCompleteLines(""), 0u);
  EXPECT_EQ(CountCompleteLines("000"), 0u);
  EXPECT_EQ(CountCompleteLines("000\r"), 1u);
  EXPECT_EQ(CountCompleteLines("000\r\n"), 1u);
  EXPECT_EQ(CountCompleteLines("00,0\r1.0E+00\r\n03"), 2u);
  EXPECT_EQ(CountCompleteLines("\r\n\r\n"), 0u);
  EXPECT_TRUE(EndsWithLineEnd("x\r"));
  EXPECT_TRUE(EndsWithLineEnd("x\n"));
  EXPECT_FALSE(EndsWithLineEnd("x"));
  EXPECT_FALSE(EndsWithLineEnd(""));
}

TEST(Printable, EscapesControlAndHighBytes) {
  EXPECT_EQ(Printable("a\r\n\x01\xff"), "a\\r\\n\\x01\\xFF");
  EXPECT_EQ(Printable("abcdef", 3), "abc...");
}

// ---- numbers -----------------------------------------------------------------------------------

TEST(ParseNumber, ReadsTheMetersFormatAndVariants) {
  EXPECT_DOUBLE_EQ(*ParseNumber("1.234E-02"), 1.234e-2);
  EXPECT_DOUBLE_EQ(*ParseNumber("9.999E+99"), 9.999e99);
  EXPECT_DOUBLE_EQ(*ParseNumber("0.000E+00"), 0.0);
  EXPECT_DOUBLE_EQ(*ParseNumber("-1.500E-03"), -1.5e-3);
  EXPECT_DOUBLE_EQ(*ParseNumber("+2.5e1"), 25.0);
  EXPECT_DOUBLE_EQ(*ParseNumber("0380."), 380.0);
  EXPECT_DOUBLE_EQ(*ParseNumber(".4476"), 0.4476);
  EXPECT_DOUBLE_EQ(*ParseNumber(" 008.0 "), 8.0);
  EXPECT_DOUBLE_EQ(*ParseNumber("42"), 42.0);
}

TEST(ParseNumber, RejectsWhatTheMeterNeverSends) {
  for (const char* bad : {"", " ", "E+02", "1.2E", "1.2E+", "1.2E+1234", "inf", "nan", "0x1p3",
                          "1.2.3", "1,2", "--1", "1e5x", ".", "+", "1.0E+0A"}) {
    EXPECT_FALSE(ParseNumber(bad).has_value()) << bad;
  }
}

// ---- status replies (B, M0) --------------------------------------------------------------------

TEST(ParseStatusReply, ReadsTheValueNotTheSpelling) {
  EXPECT_EQ(*ParseStatusReply("000\r\n", "B3"), 0);
  EXPECT_EQ(*ParseStatusReply("018\r\n", "M0"), 18);
  EXPECT_EQ(*ParseStatusReply("19\r\n", "M0"), 19);
  // "1" and "01" are the same code (an old driver compared the strings and missed it).
  EXPECT_EQ(*ParseStatusReply("1\n", "M0"), *ParseStatusReply("001\r\n", "M0"));
  EXPECT_EQ(*ParseStatusReply("000\r", "M0"), 0);
}

TEST(ParseStatusReply, MalformedRepliesNameLineAndExpectation) {
  auto r = ParseStatusReply("0a0\r\n", "M0");
  ASSERT_FALSE(r.ok());
  EXPECT_EQ(r.status().code(), StatusCode::kProtocolError);
  EXPECT_THAT(r.status().message(), HasSubstr("M0"));
  EXPECT_THAT(r.status().message(), HasSubstr("line 1"));
  EXPECT_THAT(r.status().message(), HasSubstr("0a0"));
  EXPECT_THAT(r.status().message(), HasSubstr("3-digit status"));

  EXPECT_EQ(ParseStatusReply("", "M0").status().code(), StatusCode::kProtocolError);
  EXPECT_EQ(ParseStatusReply("0000\r\n", "M0").status().code(), StatusCode::kProtocolError);
  auto two = ParseStatusReply("000\r\n000\r\n", "B3");
  EXPECT_EQ(two.status().code(), StatusCode::kProtocolError);
  EXPECT_THAT(two.status().message(), HasSubstr("2 line(s)"));
  auto noise = ParseStatusReply(
      "0\x80"
      "0\r\n",
      "B3");
  EXPECT_EQ(noise.status().code(), StatusCode::kProtocolError);
  EXPECT_THAT(noise.status().message(), HasSubstr("\\x80"));
}

// ---- setup -------------------------------------------------------------------------------------

TEST(FormatSetupCommand, MatchesTheFormsSeenInUse) {
  SetupFields f;
  EXPECT_EQ(*FormatSetupCommand(f), "S01,,,,,0,01,1");
  f.integration_ms = 500;
  f.averages = 12;
  f.sync = true;
  EXPECT_EQ(*FormatSetupCommand(f), "S01,,,,1,500,12,1");
  f.si_units = false;
  f.accessory = 3;
  EXPECT_EQ(*FormatSetupCommand(f), "S03,,,,1,500,12,0");
}

TEST(FormatSetupCommand, RejectsOutOfRangeFields) {
  for (const SetupFields& f :
       {SetupFields{0, false, 0, 1, true}, SetupFields{13, false, 0, 1, true},
        SetupFields{1, false, 9, 1, true}, SetupFields{1, false, 6001, 1, true},
        SetupFields{1, false, 100, 0, true}, SetupFields{1, false, 100, 100, true}}) {
    auto r = FormatSetupCommand(f);
    EXPECT_EQ(r.status().code(), StatusCode::kInvalidArgument);
  }
  EXPECT_TRUE(FormatSetupCommand(SetupFields{1, false, 10, 99, true}).ok());
  EXPECT_TRUE(FormatSetupCommand(SetupFields{12, false, 6000, 1, true}).ok());
}

TEST(ParseSetupReply, CodesAndTheirMeaning) {
  EXPECT_EQ(*ParseSetupReply("00\r\n"), 0);
  EXPECT_EQ(*ParseSetupReply("06\r\n"), 6);
  EXPECT_EQ(*ParseSetupReply("50\r\n"), 50);
  EXPECT_THAT(DescribeSetupReply(6), HasSubstr("integration time"));
  EXPECT_THAT(DescribeSetupReply(1), HasSubstr("lens"));
  EXPECT_THAT(DescribeSetupReply(50), HasSubstr("accessory"));
  EXPECT_THAT(DescribeSetupReply(77), HasSubstr("unknown"));
  EXPECT_EQ(ParseSetupReply("ok\r\n").status().code(), StatusCode::kProtocolError);
}

TEST(BacklightCommand, OnlyLevelsZeroToThree) {
  EXPECT_EQ(*BacklightCommand(0), "B0");
  EXPECT_EQ(*BacklightCommand(3), "B3");
  EXPECT_FALSE(BacklightCommand(4).has_value());
  EXPECT_FALSE(BacklightCommand(-1).has_value());
}

// ---- F, D1, D2 ---------------------------------------------------------------------------------

TEST(ParseFlickerReply, TextAfterTheFrequencyIsIgnored) {
  for (const char* reply : {"00,100.0 Hz\r\n", "00,100.0,1\r\n", "00,100.0Hz\r\n",
                            "00,1.000E+02 hz\r\n", "00,100.0\r\nREADY\r\n"}) {
    auto r = ParseFlickerReply(reply);
    ASSERT_TRUE(r.ok()) << reply << ": " << r.status().ToString();
    EXPECT_DOUBLE_EQ(r->frequency_hz, 100.0) << reply;
    EXPECT_EQ(r->quality_code, 0);
  }
  EXPECT_EQ(ParseFlickerReply("00,Hz\r\n").status().code(), StatusCode::kProtocolError);
}

TEST(ParseStatusReply, MinusOneIsNoMeasurement) {
  EXPECT_EQ(*ParseStatusReply("-1\r\n", "M0"), kNoMeasurementStatus);
  EXPECT_TRUE(IsNoMeasurementReply("-1\r\n"));
  EXPECT_TRUE(IsNoMeasurementReply(" -1 \r\n"));
  EXPECT_FALSE(IsNoMeasurementReply("-1\r\n00,0\r\n"));
  EXPECT_FALSE(IsNoMeasurementReply("000\r\n"));
  EXPECT_EQ(ParseStatusReply("-2\r\n", "M0").status().code(), StatusCode::kProtocolError);
}

TEST(ParseFlickerReply, QualityAndFrequency) {
  auto r = ParseFlickerReply("00,100.0\r\n");
  ASSERT_TRUE(r.ok()) << r.status().ToString();
  EXPECT_EQ(r->quality_code, 0);
  EXPECT_DOUBLE_EQ(r->frequency_hz, 100.0);
  EXPECT_EQ(ParseFlickerReply("07,0.0\r\n")->quality_code, 7);
  EXPECT_EQ(ParseFlickerReply("00\r\n").status().code(), StatusCode::kProtocolError);
  EXPECT_EQ(ParseFlickerReply("00,fast\r\n").status().code(), StatusCode::kProtocolError);
}

TEST(ParseColorimetryReply, YxyLine) {
  auto r = ParseColorimetryReply("00,0,1.234E+02,.4476,.4074\r\n");
  ASSERT_TRUE(r.ok()) << r.status().ToString();
  EXPECT_EQ(r->quality_code, 0);
  EXPECT_EQ(r->units_code, 0);
  EXPECT_DOUBLE_EQ(r->luminance, 123.4);
  EXPECT_DOUBLE_EQ(r->x, 0.4476);
  EXPECT_DOUBLE_EQ(r->y, 0.4074);
  EXPECT_EQ(ParseColorimetryReply("00,0,1.234E+02,.4476\r\n").status().code(),
            StatusCode::kProtocolError);
  EXPECT_EQ(ParseColorimetryReply("00,10,1.0E+00,.4,.4\r\n").status().code(),
            StatusCode::kProtocolError);
}

TEST(ParseTristimulusReply, XyzLine) {
  auto r = ParseTristimulusReply("18,1,9.505E+01,1.000E+02,1.089E+02\r\n");
  ASSERT_TRUE(r.ok()) << r.status().ToString();
  EXPECT_EQ(r->quality_code, 18);
  EXPECT_EQ(r->units_code, 1);
  EXPECT_DOUBLE_EQ(r->X, 95.05);
  EXPECT_DOUBLE_EQ(r->Y, 100.0);
  EXPECT_DOUBLE_EQ(r->Z, 108.9);
  auto bad = ParseTristimulusReply("00,0,9.505E+01,x,1.089E+02\r\n");
  EXPECT_EQ(bad.status().code(), StatusCode::kProtocolError);
  EXPECT_THAT(bad.status().message(), HasSubstr("field 4"));
}

// ---- D110, D120 --------------------------------------------------------------------------------

TEST(ParseSerialNumberReply, TrimsBlankPadding) {
  EXPECT_EQ(*ParseSerialNumberReply("60925301\r\n"), "60925301");
  EXPECT_EQ(*ParseSerialNumberReply("6092    \r\n"), "6092");
  EXPECT_EQ(ParseSerialNumberReply("\r\n").status().code(), StatusCode::kProtocolError);
  EXPECT_EQ(ParseSerialNumberReply("60\x01"
                                   "25\r\n")
                .status()
                .code(),
            StatusCode::kProtocolError);
}

TEST(ParseLayoutReply, ThePr650Layout) {
  auto r = ParseLayoutReply("0101,008.0,0380.,0780.,004.\r\n");
  ASSERT_TRUE(r.ok()) << r.status().ToString();
  EXPECT_EQ(r->points, 101);
  EXPECT_DOUBLE_EQ(r->bandwidth_nm, 8.0);
  EXPECT_DOUBLE_EQ(r->first_nm, 380.0);
  EXPECT_DOUBLE_EQ(r->last_nm, 780.0);
  EXPECT_DOUBLE_EQ(r->step_nm, 4.0);
  EXPECT_EQ(r->grid(), WavelengthGrid::Pr650());
  // Another meter's layout parses too (PR-670: 201 points at 2 nm).
  EXPECT_EQ(ParseLayoutReply("0201,005.0,0380.,0780.,002.\r\n")->grid(),
            (WavelengthGrid{380, 2, 201}));
}

TEST(ParseLayoutReply, InconsistentOrMalformedLayouts) {
  for (const char* bad : {"0101,008.0,0380.,0784.,004.\r\n",  // last does not follow
                          "0101,008.0,0380.,0780.\r\n",       // 4 fields
                          "01a1,008.0,0380.,0780.,004.\r\n",  // points not digits
                          "0101,008.0,0380.,0780.,000.\r\n",  // zero step
                          "0001,008.0,0380.,0380.,004.\r\n",  // one point
                          "0101,008.0,0380.,0780.,004.\r\n0101\r\n"}) {
    auto r = ParseLayoutReply(bad);
    EXPECT_EQ(r.status().code(), StatusCode::kProtocolError) << Printable(bad);
    EXPECT_THAT(r.status().message(), HasSubstr("D120"));
  }
}

// ---- D5 ----------------------------------------------------------------------------------------

TEST(ParseSpectrumReply, FullReport) {
  const std::string report = SpectrumReport("00,0", "2.345E+01", 101);
  EXPECT_EQ(report.size(), 6u + 11u + 101u * 17u);  // the byte count the reference gives
  auto r = ParseSpectrumReply(report, WavelengthGrid::Pr650());
  ASSERT_TRUE(r.ok()) << r.status().ToString();
  EXPECT_EQ(r->quality_code, 0);
  EXPECT_EQ(r->units_code, 0);
  EXPECT_DOUBLE_EQ(r->integrated, 23.45);
  EXPECT_EQ(r->grid, WavelengthGrid::Pr650());
  ASSERT_EQ(r->values.size(), 101u);
  EXPECT_DOUBLE_EQ(r->values.front(), 1e-3);
  EXPECT_DOUBLE_EQ(r->values.back(), 0.101);
}

TEST(ParseSpectrumReply, HeaderRunTogetherWithBareCrAndOtherLineEnds) {
  std::string joined = SpectrumReport("18,0", "2.345E+01", 101);
  joined.replace(joined.find("\r\n"), 2, "\r");  // "18,0\r2.345E+01\r\n..."
  auto r = ParseSpectrumReply(joined, WavelengthGrid::Pr650());
  ASSERT_TRUE(r.ok()) << r.status().ToString();
  EXPECT_EQ(r->quality_code, 18);
  EXPECT_DOUBLE_EQ(r->integrated, 23.45);
  EXPECT_EQ(ParseSpectrumReply(SpectrumReport("00,0", "1.0E+00", 101, "\n")).value().values.size(),
            101u);
  EXPECT_EQ(ParseSpectrumReply(SpectrumReport("00,0", "1.0E+00", 101, "\r")).value().values.size(),
            101u);
}

TEST(ParseSpectrumReply, WithoutExpectedGridTakesTheReportsOwn) {
  auto r = ParseSpectrumReply(SpectrumReport("00,2", "1.0E+00", 201, "\r\n", 380, 2));
  ASSERT_TRUE(r.ok()) << r.status().ToString();
  EXPECT_EQ(r->grid, (WavelengthGrid{380, 2, 201}));
  EXPECT_EQ(r->units_code, 2);
}

TEST(ParseSpectrumReply, MalformedReportsNameTheLine) {
  struct Case {
    std::string reply;
    std::string expect_in_message;
  };
  std::string bad_value = SpectrumReport("00,0", "1.0E+00", 101);
  bad_value.replace(bad_value.find("0400.,"), 15, "0400.,1.0X0E-02");
  std::string uneven = SpectrumReport("00,0", "1.0E+00", 101);
  uneven.replace(uneven.find("0400."), 5, "0401.");
  std::string noisy = SpectrumReport("00,0", "1.0E+00", 101);
  noisy[40] = '\x7f';
  const Case cases[] = {
      {SpectrumReport("0,0,0", "1.0E+00", 101), "line 1"},
      {SpectrumReport("00,10", "1.0E+00", 101), "line 1"},
      {SpectrumReport("00,0", "lots", 101), "line 2"},
      {bad_value, "line 8"},  // 0400 is the 6th band: line 2 + 6
      {uneven, "line 8"},
      {SpectrumReport("00,0", "1.0E+00", 100), "102 line(s)"},
      {SpectrumReport("00,0", "1.0E+00", 101, "\r\n", 384), "380"},
      {SpectrumReport("00,0", "1.0E+00", 101, "\r\n", 380, 2), "D120"},
      {noisy, "printable"},
      {"00,0\r\n", "1 line(s)"},
  };
  for (const Case& c : cases) {
    for (std::string_view command : {kSpectrumCommand, kMeasureSpectrumCommand}) {
      auto r = ParseSpectrumReply(c.reply, WavelengthGrid::Pr650(), command);
      ASSERT_FALSE(r.ok()) << Printable(c.reply);
      EXPECT_EQ(r.status().code(), StatusCode::kProtocolError);
      EXPECT_THAT(r.status().message(), HasSubstr("reply to " + std::string(command)));
      EXPECT_THAT(r.status().message(), HasSubstr(c.expect_in_message)) << r.status().message();
    }
  }
}

TEST(ParseSpectrumHeader, QualityAndUnitsFromTheStatusLineAlone) {
  auto h = ParseSpectrumHeader("18,0");
  ASSERT_TRUE(h.ok()) << h.status().ToString();
  EXPECT_EQ(h->quality_code, 18);
  EXPECT_EQ(h->units_code, 0);
  h = ParseSpectrumHeader("00,2", kMeasureSpectrumCommand);
  ASSERT_TRUE(h.ok()) << h.status().ToString();
  EXPECT_EQ(h->quality_code, 0);
  EXPECT_EQ(h->units_code, 2);
  for (std::string_view bad : {"", "00", "0a,0", "00,10", "00,0,1", "1.234E+01"}) {
    auto r = ParseSpectrumHeader(bad, kMeasureSpectrumCommand);
    ASSERT_FALSE(r.ok()) << bad;
    EXPECT_EQ(r.status().code(), StatusCode::kProtocolError);
    EXPECT_THAT(r.status().message(), HasSubstr("M5"));
    EXPECT_THAT(r.status().message(), HasSubstr("qq,U"));
  }
}

TEST(ParseSpectrumReply, DecreasingWavelengthsAreRejected) {
  std::string out = "00,0\r\n1.0E+00\r\n0780.,1.0E+00\r\n0776.,1.0E+00\r\n0772.,1.0E+00\r\n";
  EXPECT_EQ(ParseSpectrumReply(out).status().code(), StatusCode::kProtocolError);
}

}  // namespace
}  // namespace brdf::drivers::pr650
