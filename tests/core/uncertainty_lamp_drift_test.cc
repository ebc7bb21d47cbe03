// core/uncertainty/lamp_drift: the lamp's change between white references, cosine-corrected and
// robust to a noisy band, and the share of it a sample reading carries.
#include <gtest/gtest.h>

#include <cmath>
#include <numbers>

#include "core/uncertainty/lamp_drift.h"

namespace brdf::uncertainty {
namespace {

ReferenceObservation Ref(std::vector<double> net, double time_s, double theta_r_deg = 0) {
  return ReferenceObservation{std::move(net), theta_r_deg, time_s};
}

TEST(LampDrift, MedianRelativeChangeIgnoresAnOutlyingBand) {
  // Bands change by +1 %, +1 %, +1 % and one noisy band by +50 %: the median says 1 %.
  Result<double> change =
      RelativeChange(Ref({0.1, 0.2, 0.3, 0.4}, 0), Ref({0.101, 0.202, 0.303, 0.6}, 60));
  ASSERT_TRUE(change.ok()) << change.status().message();
  EXPECT_NEAR(*change, 0.01, 1e-12);
}

TEST(LampDrift, TheWhitesCosineIsTakenOut) {
  // The second reference is read at θr = 60°: half the light from the same lamp, no drift.
  Result<double> change = RelativeChange(Ref({0.2, 0.4}, 0), Ref({0.1, 0.2}, 60, 60));
  ASSERT_TRUE(change.ok());
  EXPECT_NEAR(*change, 0.0, 1e-12);
}

TEST(LampDrift, DarkBandsAreLeftOutAndAllDarkIsAnError) {
  Result<double> change = RelativeChange(Ref({0.0, 0.2, 0.3}, 0), Ref({0.5, 0.198, 0.297}, 1));
  ASSERT_TRUE(change.ok());
  EXPECT_NEAR(*change, -0.01, 1e-12);
  EXPECT_FALSE(RelativeChange(Ref({0.0, -1.0}, 0), Ref({0.1, 0.1}, 1)).ok());
  EXPECT_FALSE(RelativeChange(Ref({0.1}, 0), Ref({0.1, 0.1}, 1)).ok());
}

TEST(LampDrift, ShareWithinTheIntervalToTheNextReference) {
  Result<std::optional<LampDrift>> drift =
      DriftOfReading(130, Ref({0.2}, 100), std::nullopt, Ref({0.204}, 200), std::nullopt);
  ASSERT_TRUE(drift.ok()) << drift.status().message();
  ASSERT_TRUE(drift->has_value());
  EXPECT_NEAR((*drift)->change, 0.02, 1e-12);
  EXPECT_NEAR((*drift)->share, 0.3, 1e-12);
}

TEST(LampDrift, AfterTheLastReferenceThePreviousRateGoesOn) {
  // From 0 s to 100 s the lamp fell 1 %; a reading 50 s after the last reference carries half.
  Result<std::optional<LampDrift>> drift =
      DriftOfReading(150, Ref({0.099}, 100), Ref({0.1}, 0), std::nullopt, 0.5);
  ASSERT_TRUE(drift.ok());
  ASSERT_TRUE(drift->has_value());
  EXPECT_NEAR((*drift)->change, -0.01, 1e-12);
  EXPECT_NEAR((*drift)->share, 0.5, 1e-12);
}

TEST(LampDrift, OneReferenceUsesTheConfiguredRateElseNotEstimated) {
  Result<std::optional<LampDrift>> rate =
      DriftOfReading(100 + 1800, Ref({0.1}, 100), std::nullopt, std::nullopt, -0.002);
  ASSERT_TRUE(rate.ok());
  ASSERT_TRUE(rate->has_value());
  EXPECT_DOUBLE_EQ((*rate)->change, -0.002);
  EXPECT_DOUBLE_EQ((*rate)->share, 0.5);
  Result<std::optional<LampDrift>> none =
      DriftOfReading(150, Ref({0.1}, 100), std::nullopt, std::nullopt, std::nullopt);
  ASSERT_TRUE(none.ok());
  EXPECT_FALSE(none->has_value());
}

TEST(LampDrift, ReferencesOutOfOrderAreRefused) {
  Result<std::optional<LampDrift>> drift =
      DriftOfReading(150, Ref({0.1}, 100), std::nullopt, Ref({0.1}, 90), std::nullopt);
  EXPECT_FALSE(drift.ok());
  EXPECT_NE(drift.status().message().find("next reference"), std::string::npos);
}

}  // namespace
}  // namespace brdf::uncertainty
