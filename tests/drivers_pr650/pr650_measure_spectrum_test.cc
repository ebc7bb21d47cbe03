// MeasureSpectrum: a reading in one M5 exchange (the D5 report follows the measurement in its
// reply), the quality policy applied to the report's status line as it arrives, and the caller
// told then, while the bands still stream in. The real driver against the simulator's PR-650
// endpoint on a pty, as in pr650_driver_test.cc.
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include "drivers/pr650/pr650_spectroradiometer.h"
#include "tests/drivers_pr650/pr650_test_rig.h"

namespace brdf::testing {
namespace {

using namespace std::chrono_literals;
using ::testing::ElementsAre;
using ::testing::HasSubstr;
using SteadyClock = std::chrono::steady_clock;

// What the `measured` callback saw.
struct MeasuredCalls {
  std::vector<drivers::MeasurementOutcome> outcomes;
  SteadyClock::time_point last_at;

  drivers::MeasuredCallback Callback() {
    return [this](const drivers::MeasurementOutcome& outcome) {
      outcomes.push_back(outcome);
      last_at = SteadyClock::now();
    };
  }
};

// The commands after connecting and configuring (B3, S…).
std::vector<std::string> CommandsAfterSetup(const sim::Pr650Endpoint& endpoint) {
  std::vector<std::string> all = endpoint.commands();
  return {all.begin() + 2, all.end()};
}

TEST_F(Pr650DriverTest, AReadingIsOneM5Exchange) {
  auto meter = Configured(400);
  backend_.set_level(0.0456);
  MeasuredCalls calls;
  auto taken = meter->MeasureSpectrum(Ctx(), calls.Callback());
  ASSERT_TRUE(taken.ok()) << taken.status().ToString();
  EXPECT_THAT(CommandsAfterSetup(*endpoint_), ElementsAre("M5"));

  EXPECT_EQ(taken->outcome.quality_code, 0);
  EXPECT_FALSE(taken->outcome.flagged);
  EXPECT_EQ(taken->outcome.attempts, 1);
  EXPECT_EQ(taken->outcome.integration_ms, 400);
  EXPECT_EQ(taken->report.grid, WavelengthGrid::Pr650());
  EXPECT_EQ(taken->report.quality_code, 0);
  ExpectSpectrumOf(taken->report, 0.0456);

  ASSERT_EQ(calls.outcomes.size(), 1u);
  EXPECT_EQ(calls.outcomes[0].quality_code, 0);
  EXPECT_EQ(calls.outcomes[0].attempts, 1);

  // The meter still holds the measurement: D5 sends the same spectrum again.
  auto again = meter->TransferSpectrum(Ctx());
  ASSERT_TRUE(again.ok()) << again.status().ToString();
  ExpectSpectrumOf(*again, 0.0456);
}

TEST_F(Pr650DriverTest, MeasuredIsCalledBeforeTheBandsHaveArrived) {
  auto meter = Configured(100);
  MeasuredCalls calls;
  auto taken = meter->MeasureSpectrum(Ctx(), calls.Callback());
  ASSERT_TRUE(taken.ok()) << taken.status().ToString();
  ASSERT_EQ(calls.outcomes.size(), 1u);
  // ~1,730 bytes at 9600 baud are 1.8 s simulated, 180 ms of real time at the rig's scale of 10;
  // the status line is the first 6 bytes of them.
  EXPECT_GE(SteadyClock::now() - calls.last_at, 120ms);
}

TEST_F(Pr650DriverTest, TheStatusLineIsJudgedByTheQualityPolicy) {
  auto meter = Configured(500);
  InjectQuality(19, 1);  // overload: halve the integration time and measure again
  MeasuredCalls calls;
  auto taken = meter->MeasureSpectrum(Ctx(), calls.Callback());
  ASSERT_TRUE(taken.ok()) << taken.status().ToString();
  EXPECT_THAT(CommandsAfterSetup(*endpoint_), ElementsAre("M5", "S01,,,,,250,01,1", "M5"));
  EXPECT_EQ(taken->outcome.attempts, 2);
  EXPECT_EQ(taken->outcome.integration_ms, 250);
  EXPECT_EQ(taken->report.quality_code, 0);
  // Only the accepted measurement is reported as measured.
  ASSERT_EQ(calls.outcomes.size(), 1u);
  EXPECT_EQ(calls.outcomes[0].attempts, 2);
  EXPECT_EQ(calls.outcomes[0].integration_ms, 250);
}

TEST_F(Pr650DriverTest, AFlaggedMeasurementKeepsItsSpectrum) {
  auto meter = Configured(100);
  InjectQuality(18, 1);  // low light: accepted and flagged by default
  MeasuredCalls calls;
  auto taken = meter->MeasureSpectrum(Ctx(), calls.Callback());
  ASSERT_TRUE(taken.ok()) << taken.status().ToString();
  EXPECT_EQ(taken->outcome.quality_code, 18);
  EXPECT_TRUE(taken->outcome.flagged);
  EXPECT_EQ(taken->report.quality_code, 18);
  ASSERT_EQ(calls.outcomes.size(), 1u);
  EXPECT_TRUE(calls.outcomes[0].flagged);
}

TEST_F(Pr650DriverTest, AFailedMeasurementIsADeviceErrorAndNeverMeasured) {
  auto meter = Configured(100);
  InjectQuality(12, 1);  // hardware malfunction: fail
  MeasuredCalls calls;
  auto failed = meter->MeasureSpectrum(Ctx(), calls.Callback());
  ASSERT_FALSE(failed.ok());
  EXPECT_EQ(failed.status().code(), StatusCode::kDeviceError);
  EXPECT_EQ(failed.status().device_code(), 12);
  EXPECT_THAT(failed.status().message(), HasSubstr("malfunction"));
  EXPECT_TRUE(calls.outcomes.empty());
  EXPECT_EQ(meter->TransferSpectrum(Ctx()).status().code(), StatusCode::kFailedPrecondition);

  // The failed measurement's report was read to its end: the next reading is clean.
  auto taken = meter->MeasureSpectrum(Ctx(), calls.Callback());
  ASSERT_TRUE(taken.ok()) << taken.status().ToString();
  EXPECT_EQ(calls.outcomes.size(), 1u);
}

TEST_F(Pr650DriverTest, AReportCutShortAfterARejectedStatusLineIsNoError) {
  // A meter may send less than the full report after a bad measurement: the policy measures
  // again either way.
  auto meter = Configured(100);
  InjectQuality(29, 1);  // corrupted data: measure again
  control_.UpdateSerial([](sim::SerialFaults& f) { return f.truncate_next = 1; });
  MeasuredCalls calls;
  auto taken = meter->MeasureSpectrum(Ctx(), calls.Callback());
  ASSERT_TRUE(taken.ok()) << taken.status().ToString();
  EXPECT_EQ(taken->outcome.attempts, 2);
  EXPECT_EQ(CountCommand(*endpoint_, "M5"), 2);
  EXPECT_EQ(calls.outcomes.size(), 1u);
}

TEST_F(Pr650DriverTest, AReportCutShortAfterAnAcceptedStatusLineIsAnError) {
  auto meter = Configured(100);
  control_.UpdateSerial([](sim::SerialFaults& f) { return f.truncate_next = 1; });
  MeasuredCalls calls;
  auto cut = meter->MeasureSpectrum(Ctx(), calls.Callback());
  ASSERT_FALSE(cut.ok());
  EXPECT_EQ(cut.status().code(), StatusCode::kProtocolError);
  EXPECT_THAT(cut.status().message(), HasSubstr("M5"));
  EXPECT_THAT(cut.status().message(), HasSubstr("truncated"));
  // The caller was told the measurement was taken (and may have moved on): it learns of the lost
  // spectrum from the error, and measures again.
  EXPECT_EQ(calls.outcomes.size(), 1u);
  auto taken = meter->MeasureSpectrum(Ctx(), calls.Callback());
  ASSERT_TRUE(taken.ok()) << taken.status().ToString();
  EXPECT_EQ(calls.outcomes.size(), 2u);
}

TEST_F(Pr650DriverTest, WithoutMeasureWithSpectrumAReadingIsM0ThenD5) {
  options_.measure_with_spectrum = false;
  auto meter = Configured(200);
  backend_.set_level(0.0789);
  MeasuredCalls calls;
  auto taken = meter->MeasureSpectrum(Ctx(), calls.Callback());
  ASSERT_TRUE(taken.ok()) << taken.status().ToString();
  EXPECT_THAT(CommandsAfterSetup(*endpoint_), ElementsAre("M0", "D5"));
  ExpectSpectrumOf(taken->report, 0.0789);
  ASSERT_EQ(calls.outcomes.size(), 1u);
  EXPECT_GE(SteadyClock::now() - calls.last_at, 120ms);  // before the D5 transfer
}

TEST_F(Pr650DriverTest, MeasureSpectrumBeforeConnectIsRefused) {
  MeasuredCalls calls;
  auto meter = Driver();
  auto r = meter->MeasureSpectrum(Ctx(), calls.Callback());
  EXPECT_EQ(r.status().code(), StatusCode::kFailedPrecondition);
  EXPECT_TRUE(calls.outcomes.empty());
}

}  // namespace
}  // namespace brdf::testing
