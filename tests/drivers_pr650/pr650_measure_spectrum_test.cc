// MeasureSpectrum: a reading in one M5 exchange (the D5 report follows the measurement in its
// reply), the quality policy applied to the report's status line as it arrives, and the caller
// told then, while the bands still stream in. The real driver against the simulator's PR-650
// endpoint on a pty, as in pr650_driver_test.cc.
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include "drivers/pr650/spectroradiometer.h"
#include "tests/drivers_pr650/pr650_test_rig.h"

namespace brdf::testing {
namespace {

using namespace std::chrono_literals;
using ::testing::ElementsAre;
using ::testing::HasSubstr;
using ::testing::Not;
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

// The meter's own M0 reply is 000 whatever the quality: the D5 report's quality code is judged.
TEST_F(Pr650DriverTest, WithM0ThenD5TheReportsQualityIsJudged) {
  sim::Pr650EndpointOptions meter_like = FastEndpointOptions();
  meter_like.m0_reply_is_quality = false;
  StartEndpoint(meter_like);
  options_.measure_with_spectrum = false;
  auto meter = Configured(200);
  InjectQuality(18, 1);
  auto low = meter->MeasureSpectrum(Ctx(), {});
  ASSERT_TRUE(low.ok()) << low.status().ToString();
  EXPECT_EQ(low->outcome.quality_code, 18);
  EXPECT_TRUE(low->outcome.flagged);
  // Overload in the report: the integration is halved and the reading measured again.
  InjectQuality(19, 1);
  auto over = meter->MeasureSpectrum(Ctx(), {});
  ASSERT_TRUE(over.ok()) << over.status().ToString();
  EXPECT_EQ(over->outcome.quality_code, 0);
  EXPECT_EQ(over->outcome.integration_ms, 100);
  EXPECT_EQ(over->outcome.attempts, 2);
}

TEST_F(Pr650DriverTest, MinusOneIsAFailedMeasurementInBothModes) {
  auto meter = Configured(200);
  control_.UpdateSerial([](sim::SerialFaults& f) { return f.no_data_next = 1; });
  auto m5 = meter->MeasureSpectrum(Ctx(), {});
  ASSERT_EQ(m5.status().code(), StatusCode::kDeviceError) << m5.status().ToString();
  EXPECT_EQ(m5.status().device_code(), -1);
  EXPECT_THAT(m5.status().message(), HasSubstr("holds no measurement"));
  EXPECT_TRUE(meter->MeasureSpectrum(Ctx(), {}).ok());  // measured again, it works
  meter.reset();  // the port is held exclusively: the second driver opens it after the first

  options_.measure_with_spectrum = false;
  auto m0 = Configured(200);
  control_.UpdateSerial([](sim::SerialFaults& f) { return f.no_data_next = 1; });
  auto d5 = m0->MeasureSpectrum(Ctx(), {});
  ASSERT_EQ(d5.status().code(), StatusCode::kDeviceError) << d5.status().ToString();
  EXPECT_EQ(d5.status().device_code(), -1);
  EXPECT_THAT(d5.status().message(), HasSubstr("answered D5 with -1"));
}

TEST_F(Pr650DriverTest, AnUncalibratedReportIsFlaggedWithANote) {
  auto meter = Configured(200);
  control_.UpdateSerial([](sim::SerialFaults& f) { return f.units_code = 2; });
  auto taken = meter->MeasureSpectrum(Ctx(), {});
  ASSERT_TRUE(taken.ok()) << taken.status().ToString();
  EXPECT_EQ(taken->report.units_code, 2);
  EXPECT_EQ(taken->outcome.quality_code, 0);
  EXPECT_TRUE(taken->outcome.flagged);
  EXPECT_THAT(taken->outcome.note, HasSubstr("uncalibrated"));
}

TEST_F(Pr650DriverTest, TheMeasurementTimeoutFollowsIntegrationTimesAverages) {
  // A measurement of 2 × 1,000 ms takes 2 s simulated, 0.2 s real; with a 50 ms margin the reply
  // still comes within 2,050 ms. A silent meter's timeout says what it was made of.
  options_.measurement_timeout = std::chrono::milliseconds(50);
  options_.reply_timeout = std::chrono::milliseconds(400);
  auto meter = Driver();
  ASSERT_TRUE(meter->Connect(Ctx()).ok());
  ASSERT_TRUE(meter->Configure({1000, 2, false}, Ctx()).ok());
  backend_.set_default_duration(2.0);  // simulated s: 0.2 s real
  EXPECT_TRUE(meter->MeasureSpectrum(Ctx(), {}).ok());
  control_.UpdateSerial([](sim::SerialFaults& f) { return f.silent = true; });
  auto silent = meter->MeasureSpectrum(Ctx(), {});
  ASSERT_EQ(silent.status().code(), StatusCode::kTimeout);
  EXPECT_THAT(silent.status().message(), HasSubstr("within 2050 ms (2 average(s) of 1000 ms"));
  EXPECT_THAT(silent.status().message(), Not(HasSubstr("switched off")));
}

TEST(MeasurementReplyTimeout, IntegrationTimesAveragesPlusTheMargin) {
  drivers::Pr650Options o;
  EXPECT_EQ(drivers::MeasurementReplyTimeout(o, 6000, 99).count(), 30000 + 594000);
  EXPECT_EQ(drivers::MeasurementReplyTimeout(o, 0, 2).count(), 30000 + 12000);  // adaptive
  EXPECT_EQ(drivers::MeasurementReplyTimeout(o, 100, 0).count(), 30100);
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
