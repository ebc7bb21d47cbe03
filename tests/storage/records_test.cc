// The words storage writes for its enumerations, and the byte layout of a stored spectrum.
#include "storage/records.h"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <cstring>
#include <limits>

#include "storage/spectrum_blob.h"

namespace brdf::storage {
namespace {

using ::testing::HasSubstr;

TEST(RecordsTest, EveryEnumValueRoundTripsThroughItsWord) {
  for (StepKind k : {StepKind::kMove, StepKind::kPrompt, StepKind::kReference, StepKind::kDark,
                     StepKind::kSample}) {
    EXPECT_EQ(*ParseStepKind(ToString(k)), k) << ToString(k);
  }
  for (StepState s : {StepState::kPending, StepState::kDone, StepState::kSkipped}) {
    EXPECT_EQ(*ParseStepState(ToString(s)), s) << ToString(s);
  }
  for (ReadingKind k : {ReadingKind::kSample, ReadingKind::kReference, ReadingKind::kDark}) {
    EXPECT_EQ(*ParseReadingKind(ToString(k)), k) << ToString(k);
  }
  EXPECT_EQ(ToString(SessionState::kAwaitingOperator), "awaiting_operator");
  EXPECT_EQ(ToString(StepKind::kReference), "reference");
}

TEST(RecordsTest, UnknownWordIsRefusedListingTheAcceptedOnes) {
  Result<StepKind> k = ParseStepKind("measure");
  ASSERT_FALSE(k.ok());
  EXPECT_EQ(k.status().code(), StatusCode::kInvalidArgument);
  EXPECT_THAT(k.status().message(), HasSubstr("\"measure\""));
  EXPECT_THAT(k.status().message(), HasSubstr("move, prompt, reference, dark, sample"));
  EXPECT_FALSE(ParseReadingKind("Sample").ok()) << "words are lower case";
}

TEST(RecordsTest, ReadingKindFollowsStepKind) {
  EXPECT_EQ(ReadingKindFor(StepKind::kSample), ReadingKind::kSample);
  EXPECT_EQ(ReadingKindFor(StepKind::kReference), ReadingKind::kReference);
  EXPECT_EQ(ReadingKindFor(StepKind::kDark), ReadingKind::kDark);
  EXPECT_EQ(ReadingKindFor(StepKind::kMove), std::nullopt);
  EXPECT_EQ(ReadingKindFor(StepKind::kPrompt), std::nullopt);
  EXPECT_TRUE(IsActive(SessionState::kAwaitingOperator));
  EXPECT_FALSE(IsActive(SessionState::kPaused));
}

TEST(SpectrumBlobTest, IsLittleEndianFloat64) {
  const std::vector<std::uint8_t> blob = EncodeSpectrum(std::vector<double>{1.0, -2.0});
  // 1.0 = 0x3FF0000000000000, -2.0 = 0xC000000000000000, least significant byte first.
  const std::vector<std::uint8_t> expected{0, 0, 0, 0, 0, 0, 0xF0, 0x3F, 0, 0, 0, 0, 0, 0, 0, 0xC0};
  EXPECT_EQ(blob, expected);
}

TEST(SpectrumBlobTest, RoundTripsEveryBitPattern) {
  const std::vector<double> values{0.0,
                                   -0.0,
                                   1e-300,
                                   std::numeric_limits<double>::denorm_min(),
                                   std::numeric_limits<double>::infinity(),
                                   std::numeric_limits<double>::quiet_NaN(),
                                   0.1 + 0.2,
                                   -123456.789};
  Result<std::vector<double>> back = DecodeSpectrum(EncodeSpectrum(values), values.size());
  ASSERT_TRUE(back.ok());
  ASSERT_EQ(back->size(), values.size());
  for (std::size_t i = 0; i < values.size(); ++i) {
    EXPECT_EQ(std::memcmp(&(*back)[i], &values[i], sizeof(double)), 0) << i;
  }
}

TEST(SpectrumBlobTest, WrongSizeIsRefused) {
  const std::vector<std::uint8_t> blob = EncodeSpectrum(std::vector<double>(101, 0.5));
  Result<std::vector<double>> short_grid = DecodeSpectrum(blob, 100);
  ASSERT_FALSE(short_grid.ok());
  EXPECT_THAT(short_grid.status().message(), HasSubstr("808 bytes"));
  EXPECT_THAT(short_grid.status().message(), HasSubstr("100 bands need 800"));
  EXPECT_FALSE(DecodeSpectrum(std::span<const std::uint8_t>(blob).first(807), 101).ok());
}

}  // namespace
}  // namespace brdf::storage
