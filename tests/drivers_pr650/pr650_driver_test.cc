// The real PR-650 driver against the simulator's PR-650 endpoint, in-process, over a real pty.
// The endpoint and its fake optics stand in for the meter; the driver, its serial link, framing,
// parser and quality policy are the code under test.
#include <gmock/gmock.h>
#include <gtest/gtest.h>
#include <unistd.h>

#include <fstream>

#include "drivers/pr650/spectroradiometer.h"
#include "tests/drivers_pr650/pr650_test_rig.h"

namespace brdf::testing {
namespace {

using namespace std::chrono_literals;
using drivers::MeasurementSettings;
using drivers::Pr650Options;
using drivers::Pr650Spectroradiometer;
using drivers::pr650::QualityAction;
using ::testing::ElementsAre;
using ::testing::HasSubstr;
using SteadyClock = std::chrono::steady_clock;

// ---- each command path ------------------------------------------------------------------------

TEST_F(Pr650DriverTest, ConnectIdentifyConfigureMeasureTransfer) {
  auto meter = Driver();
  ASSERT_TRUE(meter->Connect(Ctx()).ok());
  EXPECT_TRUE(meter->connected());
  EXPECT_TRUE(endpoint_->remote_mode());

  auto id = meter->Identify(Ctx());
  ASSERT_TRUE(id.ok()) << id.status().ToString();
  EXPECT_EQ(id->model, "PR-650");
  EXPECT_EQ(id->serial_number, "60925301");
  EXPECT_EQ(id->grid, WavelengthGrid::Pr650());

  Status s = meter->Configure({400, 2, false}, Ctx());
  ASSERT_TRUE(s.ok()) << s.ToString();

  backend_.set_level(0.0456);
  auto outcome = meter->Measure(Ctx());
  ASSERT_TRUE(outcome.ok()) << outcome.status().ToString();
  EXPECT_EQ(outcome->quality_code, 0);
  EXPECT_FALSE(outcome->flagged);
  EXPECT_EQ(outcome->attempts, 1);
  EXPECT_EQ(outcome->integration_ms, 400);

  auto report = meter->TransferSpectrum(Ctx());
  ASSERT_TRUE(report.ok()) << report.status().ToString();
  EXPECT_EQ(report->grid, WavelengthGrid::Pr650());
  EXPECT_EQ(report->quality_code, 0);
  EXPECT_EQ(report->units_code, 0);
  ExpectSpectrumOf(*report, 0.0456);

  EXPECT_THAT(endpoint_->commands(),
              ElementsAre("B3", "D110", "D120", "S01,,,,,400,02,1", "M0", "D5"));
  ASSERT_EQ(backend_.setups().size(), 1u);
  EXPECT_EQ(backend_.setups()[0].integration_ms, 400);
  EXPECT_EQ(backend_.setups()[0].averages, 2);
}

TEST_F(Pr650DriverTest, ConnectIsIdempotentAndToleratesThePtysMissingRts) {
  auto meter = Driver();
  ASSERT_TRUE(meter->Connect(Ctx()).ok());
  ASSERT_TRUE(meter->Connect(Ctx()).ok());
  EXPECT_EQ(CountCommand(*endpoint_, "B3"), 1);
  // A pty has no modem lines: the RTS drop is logged, not fatal.
  EXPECT_TRUE(log_.Contains("RTS not supported")) << log_.All();
  meter->Disconnect();
  EXPECT_FALSE(meter->connected());
  ASSERT_TRUE(meter->Connect(Ctx()).ok());
  EXPECT_EQ(CountCommand(*endpoint_, "B3"), 2);
}

TEST_F(Pr650DriverTest, WakeCommandIsConfigurable) {
  options_.wake_backlight = 0;
  auto meter = Driver();
  ASSERT_TRUE(meter->Connect(Ctx()).ok());
  EXPECT_THAT(endpoint_->commands(), ElementsAre("B0"));
}

TEST_F(Pr650DriverTest, MeasureWithoutConfigureUsesTheMetersSetup) {
  auto meter = Driver();
  ASSERT_TRUE(meter->Connect(Ctx()).ok());
  auto outcome = meter->Measure(Ctx());
  ASSERT_TRUE(outcome.ok()) << outcome.status().ToString();
  EXPECT_EQ(outcome->integration_ms, 0);  // adaptive
  EXPECT_THAT(endpoint_->commands(), ElementsAre("B3", "M0"));
  ASSERT_TRUE(meter->TransferSpectrum(Ctx()).ok());
}

TEST_F(Pr650DriverTest, SyncToSourceMeasuresFlickerFirst) {
  auto meter = Driver();
  ASSERT_TRUE(meter->Connect(Ctx()).ok());
  ASSERT_TRUE(meter->Configure({200, 1, true}, Ctx()).ok());
  EXPECT_THAT(endpoint_->commands(), ElementsAre("B3", "F", "S01,,,,1,200,01,1"));
  EXPECT_TRUE(log_.Contains("100.0")) << log_.All();
}

TEST_F(Pr650DriverTest, CallsBeforeConnectOrMeasureAreRefused) {
  auto meter = Driver();
  EXPECT_EQ(meter->Measure(Ctx()).status().code(), StatusCode::kFailedPrecondition);
  EXPECT_EQ(meter->Identify(Ctx()).status().code(), StatusCode::kFailedPrecondition);
  ASSERT_TRUE(meter->Connect(Ctx()).ok());
  auto r = meter->TransferSpectrum(Ctx());
  EXPECT_EQ(r.status().code(), StatusCode::kFailedPrecondition);
  EXPECT_THAT(r.status().message(), HasSubstr("Measure first"));
}

TEST_F(Pr650DriverTest, BadSettingsAreRejectedBeforeReachingTheMeter) {
  auto meter = Driver();
  ASSERT_TRUE(meter->Connect(Ctx()).ok());
  EXPECT_EQ(meter->Configure({5, 1, false}, Ctx()).code(), StatusCode::kInvalidArgument);
  EXPECT_EQ(meter->Configure({100, 0, false}, Ctx()).code(), StatusCode::kInvalidArgument);
  EXPECT_EQ(meter->Configure({7000, 1, false}, Ctx()).code(), StatusCode::kInvalidArgument);
  EXPECT_EQ(CountCommand(*endpoint_, "B3"), 1);
  EXPECT_EQ(endpoint_->commands().size(), 1u);
}

TEST_F(Pr650DriverTest, SetupRejectedByTheMeterIsADeviceError) {
  options_.accessory = 2;  // the simulated meter has only the MS-75 lens (01)
  auto meter = Driver();
  ASSERT_TRUE(meter->Connect(Ctx()).ok());
  Status s = meter->Configure({100, 1, false}, Ctx());
  EXPECT_EQ(s.code(), StatusCode::kDeviceError);
  EXPECT_EQ(s.device_code(), 50);
  EXPECT_THAT(s.message(), HasSubstr("accessory"));
  EXPECT_THAT(s.message(), HasSubstr("S02,,,,,100,01,1"));
}

// ---- configuration errors ---------------------------------------------------------------------

TEST_F(Pr650DriverTest, BadOptionsAndPortNamesAreConfigurationErrors) {
  Pr650Options o = options_;
  o.port = "";
  EXPECT_EQ(Pr650Spectroradiometer(o).Connect(Ctx()).code(), StatusCode::kConfigurationError);
  o = options_;
  o.quiet_gap = 0ms;
  EXPECT_EQ(Pr650Spectroradiometer(o).Connect(Ctx()).code(), StatusCode::kConfigurationError);
  o = options_;
  o.baud = 9601;
  EXPECT_EQ(Pr650Spectroradiometer(o).Connect(Ctx()).code(), StatusCode::kConfigurationError);
  o = options_;
  o.wake_attempts = 0;
  EXPECT_EQ(Pr650Spectroradiometer(o).Connect(Ctx()).code(), StatusCode::kConfigurationError);
  o = options_;
  o.port = "/dev/ttyUSB-no-such-port";
  Status missing = Pr650Spectroradiometer(o).Connect(Ctx());
  EXPECT_EQ(missing.code(), StatusCode::kConfigurationError);
  EXPECT_THAT(missing.message(), HasSubstr("/dev/ttyUSB-no-such-port"));

  const std::string plain_file = ::testing::TempDir() + "/pr650-not-a-port";
  std::ofstream(plain_file) << "x";
  o.port = plain_file;
  EXPECT_EQ(Pr650Spectroradiometer(o).Connect(Ctx()).code(), StatusCode::kConfigurationError);
  ::unlink(plain_file.c_str());
}

// ---- quality-code policies ---------------------------------------------------------------------

TEST_F(Pr650DriverTest, OverloadHalvesTheIntegrationAndResendsSetup) {
  auto meter = Configured(400);
  InjectQuality(19, 2);
  auto outcome = meter->Measure(Ctx());
  ASSERT_TRUE(outcome.ok()) << outcome.status().ToString();
  EXPECT_EQ(outcome->quality_code, 0);
  EXPECT_EQ(outcome->attempts, 3);
  EXPECT_EQ(outcome->integration_ms, 100);
  EXPECT_FALSE(outcome->flagged);
  EXPECT_THAT(outcome->note, HasSubstr("halved from 400 to 200 ms"));
  EXPECT_THAT(outcome->note, HasSubstr("halved from 200 to 100 ms"));
  EXPECT_THAT(MeasuredIntegrations(), ElementsAre(400, 200, 100));
  EXPECT_EQ(CountCommand(*endpoint_, "S01,,,,,100,01,1"), 1);
  ASSERT_TRUE(meter->TransferSpectrum(Ctx()).ok());

  // The next measurement starts from the configured 400 ms again.
  ASSERT_TRUE(meter->Measure(Ctx()).ok());
  EXPECT_EQ(MeasuredIntegrations().back(), 400);
}

TEST_F(Pr650DriverTest, OverloadAtTheShortestIntegrationFails) {
  auto meter = Configured(10);
  InjectQuality(19, 1);
  auto outcome = meter->Measure(Ctx());
  ASSERT_FALSE(outcome.ok());
  EXPECT_EQ(outcome.status().code(), StatusCode::kDeviceError);
  EXPECT_EQ(outcome.status().device_code(), 19);
  EXPECT_THAT(outcome.status().message(), HasSubstr("10 ms minimum"));
  // Nothing usable is held: the transfer is refused.
  EXPECT_EQ(meter->TransferSpectrum(Ctx()).status().code(), StatusCode::kFailedPrecondition);
}

TEST_F(Pr650DriverTest, OverloadWithAdaptiveIntegrationFails) {
  auto meter = Configured(0);
  InjectQuality(19, 1);
  auto outcome = meter->Measure(Ctx());
  EXPECT_EQ(outcome.status().device_code(), 19);
  EXPECT_THAT(outcome.status().message(), HasSubstr("adaptive"));
}

TEST_F(Pr650DriverTest, WeakSignalDoublesUpToTheLimitThenFails) {
  auto meter = Configured(3000);
  InjectQuality(10, 1);
  auto outcome = meter->Measure(Ctx());
  ASSERT_TRUE(outcome.ok()) << outcome.status().ToString();
  EXPECT_EQ(outcome->integration_ms, 6000);
  EXPECT_EQ(outcome->attempts, 2);

  InjectQuality(10, 5);
  outcome = meter->Measure(Ctx());
  ASSERT_FALSE(outcome.ok());
  EXPECT_EQ(outcome.status().device_code(), 10);
  EXPECT_THAT(outcome.status().message(), HasSubstr("6000 ms maximum"));
}

TEST_F(Pr650DriverTest, LowLightIsFlaggedByDefault) {
  auto meter = Configured(500);
  InjectQuality(18, 1);
  auto outcome = meter->Measure(Ctx());
  ASSERT_TRUE(outcome.ok()) << outcome.status().ToString();
  EXPECT_EQ(outcome->quality_code, 18);
  EXPECT_TRUE(outcome->flagged);
  EXPECT_EQ(outcome->attempts, 1);
  auto report = meter->TransferSpectrum(Ctx());
  ASSERT_TRUE(report.ok()) << report.status().ToString();
  EXPECT_EQ(report->quality_code, 18);  // the D5 header repeats the code
}

TEST_F(Pr650DriverTest, LowLightCanBeSetToAdaptTheIntegration) {
  options_.quality_policy.Set(18, {QualityAction::kAdaptIntegration, true});
  auto meter = Configured(500);
  InjectQuality(18, 1);
  auto outcome = meter->Measure(Ctx());
  ASSERT_TRUE(outcome.ok()) << outcome.status().ToString();
  EXPECT_FALSE(outcome->flagged);
  EXPECT_EQ(outcome->integration_ms, 1000);
  EXPECT_THAT(MeasuredIntegrations(), ElementsAre(500, 1000));
}

TEST_F(Pr650DriverTest, SyncLossSwitchesSyncOffAndMeasuresAgain) {
  auto meter = Driver();
  ASSERT_TRUE(meter->Connect(Ctx()).ok());
  ASSERT_TRUE(meter->Configure({200, 1, true}, Ctx()).ok());
  InjectQuality(8, 1);
  auto outcome = meter->Measure(Ctx());
  ASSERT_TRUE(outcome.ok()) << outcome.status().ToString();
  EXPECT_EQ(outcome->attempts, 2);
  EXPECT_THAT(outcome->note, HasSubstr("sync switched off"));
  EXPECT_THAT(endpoint_->commands(),
              ElementsAre("B3", "F", "S01,,,,1,200,01,1", "M0", "S01,,,,,200,01,1", "M0"));
}

TEST_F(Pr650DriverTest, RetryCodesMeasureAgain) {
  for (int code : {16, 29}) {
    auto meter = Configured(100);
    InjectQuality(code, 1);
    auto outcome = meter->Measure(Ctx());
    ASSERT_TRUE(outcome.ok()) << code << ": " << outcome.status().ToString();
    EXPECT_EQ(outcome->attempts, 2) << code;
    EXPECT_EQ(outcome->quality_code, 0);
    EXPECT_FALSE(outcome->flagged);
  }
}

TEST_F(Pr650DriverTest, RetriesAreBoundedByMaxAttempts) {
  options_.max_measure_attempts = 3;
  auto meter = Configured(100);
  InjectQuality(29, 10);
  auto failed = meter->Measure(Ctx());
  EXPECT_EQ(failed.status().device_code(), 29);
  EXPECT_THAT(failed.status().message(), HasSubstr("3 attempt(s)"));

  InjectQuality(30, 10);  // noisy: retried, then kept but flagged
  auto noisy = meter->Measure(Ctx());
  ASSERT_TRUE(noisy.ok()) << noisy.status().ToString();
  EXPECT_TRUE(noisy->flagged);
  EXPECT_EQ(noisy->attempts, 3);
  EXPECT_EQ(noisy->quality_code, 30);
}

TEST_F(Pr650DriverTest, ErrorCodesFailWithTheCodeAndAHint) {
  auto meter = Configured(100);
  for (int code : {1, 3, 4, 5, 6, 12, 13, 14, 17, 20, 21, 42, 99}) {
    InjectQuality(code, 1);
    auto outcome = meter->Measure(Ctx());
    ASSERT_FALSE(outcome.ok()) << code;
    EXPECT_EQ(outcome.status().code(), StatusCode::kDeviceError) << code;
    EXPECT_EQ(outcome.status().device_code(), code);
  }
  InjectQuality(17, 1);
  EXPECT_THAT(meter->Measure(Ctx()).status().message(), HasSubstr("battery"));
  InjectQuality(42, 1);
  EXPECT_THAT(meter->Measure(Ctx()).status().message(), HasSubstr("unknown quality code"));
  // Still talking to the meter afterwards.
  ASSERT_TRUE(meter->Measure(Ctx()).ok());
}

TEST_F(Pr650DriverTest, QualityFromTheOpticsIsHandledLikeAnInjectedOne) {
  auto meter = Configured(800);
  backend_.set_quality(18);
  auto outcome = meter->Measure(Ctx());
  ASSERT_TRUE(outcome.ok());
  EXPECT_TRUE(outcome->flagged);
}

// ---- delivery variants ------------------------------------------------------------------------

class Pr650WireTest : public Pr650DriverTest,
                      public ::testing::WithParamInterface<sim::Pr650WireQuirks> {};

TEST_P(Pr650WireTest, FullCycleWorks) {
  sim::Pr650EndpointOptions o = FastEndpointOptions();
  o.quirks = GetParam();
  StartEndpoint(o);
  auto meter = Driver();
  ASSERT_TRUE(meter->Connect(Ctx()).ok()) << log_.All();
  auto id = meter->Identify(Ctx());
  ASSERT_TRUE(id.ok()) << id.status().ToString();
  EXPECT_EQ(id->serial_number, "60925301");
  ASSERT_TRUE(meter->Configure({100, 1, false}, Ctx()).ok());
  ASSERT_TRUE(meter->Measure(Ctx()).ok());
  auto report = meter->TransferSpectrum(Ctx());
  ASSERT_TRUE(report.ok()) << report.status().ToString();
  ExpectSpectrumOf(*report, backend_.level());
}

sim::Pr650WireQuirks Quirks(sim::Pr650WireQuirks::LineEnding eol, bool bare_cr, int piece_bytes,
                            std::chrono::milliseconds piece_gap,
                            std::chrono::milliseconds delay = 0ms) {
  sim::Pr650WireQuirks q;
  q.line_ending = eol;
  q.d5_header_bare_cr = bare_cr;
  q.piece_bytes = piece_bytes;
  q.piece_gap = piece_gap;
  q.reply_delay = delay;
  return q;
}

using Eol = sim::Pr650WireQuirks::LineEnding;
INSTANTIATE_TEST_SUITE_P(
    LineEndsAndPieces, Pr650WireTest,
    ::testing::Values(Quirks(Eol::kCrLf, false, 0, 0ms), Quirks(Eol::kLf, false, 0, 0ms),
                      Quirks(Eol::kCr, false, 0, 0ms),
                      Quirks(Eol::kCrLf, true, 0, 0ms),    // D5 header joined by a bare CR
                      Quirks(Eol::kCrLf, false, 16, 5ms),  // pieces inside the quiet gap
                      // pieces further apart than the quiet gap (20 ms) but within the stall
                      // timeout: the reader waits for the lines it expects
                      Quirks(Eol::kCrLf, false, 200, 60ms),
                      // every reply starts late in the wait (300 of 400 ms)
                      Quirks(Eol::kCrLf, false, 0, 0ms, 300ms)));

// A reply that comes after its command timed out, while the driver already retries: it is
// discarded, never taken as the retry's answer (which would leave every later reply one behind:
// the layout query D120 read the serial number once under load).
TEST_F(Pr650DriverTest, AReplyLaterThanItsTimeoutIsNotTakenForTheNextCommands) {
  sim::Pr650EndpointOptions o = FastEndpointOptions();
  // The reply timeout is 400 ms: the first wake-up attempt times out, its reply comes while the
  // second attempt waits, and the second attempt's own reply comes after the next command went out.
  o.quirks.reply_delay = 550ms;
  o.quirks.delayed_replies = 2;
  StartEndpoint(o);
  auto meter = Driver();
  ASSERT_TRUE(meter->Connect(Ctx()).ok()) << log_.All();
  auto id = meter->Identify(Ctx());
  ASSERT_TRUE(id.ok()) << id.status().ToString() << "\n" << log_.All();
  EXPECT_EQ(id->serial_number, "60925301");
  EXPECT_EQ(id->grid.count, 101u);
  ASSERT_TRUE(meter->Configure({100, 1, false}, Ctx()).ok());
  ASSERT_TRUE(meter->Measure(Ctx()).ok());
  auto report = meter->TransferSpectrum(Ctx());
  ASSERT_TRUE(report.ok()) << report.status().ToString();
  ExpectSpectrumOf(*report, backend_.level());
}

// ---- link failures ----------------------------------------------------------------------------

TEST_F(Pr650DriverTest, SilentMeterTimesOutWithTheOperatorHint) {
  control_.set_serial({.silent = true});
  auto meter = Driver();
  Status s = meter->Connect(Ctx());
  EXPECT_EQ(s.code(), StatusCode::kTimeout);
  EXPECT_THAT(s.message(), HasSubstr("3 attempts"));
  EXPECT_THAT(s.message(), HasSubstr("Power-cycle the meter"));
  EXPECT_THAT(s.message(), HasSubstr("5 s"));
  EXPECT_THAT(s.message(), HasSubstr("XFER/CTRLR"));
  EXPECT_FALSE(meter->connected());
  EXPECT_EQ(CountCommand(*endpoint_, "B3"), 3);
}

TEST_F(Pr650DriverTest, MissedWakeWindowNeedsAPowerCycle) {
  sim::Pr650EndpointOptions o = FastEndpointOptions();
  o.wake_window_s = 0.5;  // 50 ms real
  StartEndpoint(o);
  std::this_thread::sleep_for(100ms);
  auto meter = Driver();
  EXPECT_EQ(meter->Connect(Ctx()).code(), StatusCode::kTimeout);
  EXPECT_FALSE(endpoint_->remote_mode());

  endpoint_->PowerCycle();
  Status s = meter->Connect(Ctx());
  ASSERT_TRUE(s.ok()) << s.ToString();
  EXPECT_TRUE(endpoint_->remote_mode());
}

TEST_F(Pr650DriverTest, GarbageIsAProtocolErrorAndTheNextCallRecovers) {
  auto meter = Driver();
  ASSERT_TRUE(meter->Connect(Ctx()).ok());
  control_.UpdateSerial([](sim::SerialFaults& f) { return f.garbage_next = 1; });
  auto id = meter->Identify(Ctx());
  ASSERT_FALSE(id.ok());
  EXPECT_EQ(id.status().code(), StatusCode::kProtocolError);
  EXPECT_THAT(id.status().message(), HasSubstr("D110"));
  EXPECT_TRUE(meter->connected());
  ASSERT_TRUE(meter->Identify(Ctx()).ok());

  ASSERT_TRUE(meter->Measure(Ctx()).ok());
  control_.UpdateSerial([](sim::SerialFaults& f) { return f.garbage_next = 1; });
  auto report = meter->TransferSpectrum(Ctx());
  EXPECT_EQ(report.status().code(), StatusCode::kProtocolError);
  EXPECT_THAT(report.status().message(), HasSubstr("D5"));
  ASSERT_TRUE(meter->TransferSpectrum(Ctx()).ok());
}

TEST_F(Pr650DriverTest, TruncatedRepliesAreProtocolErrors) {
  auto meter = Configured(100);
  control_.UpdateSerial([](sim::SerialFaults& f) { return f.truncate_next = 1; });
  auto outcome = meter->Measure(Ctx());
  EXPECT_EQ(outcome.status().code(), StatusCode::kProtocolError);
  EXPECT_THAT(outcome.status().message(), HasSubstr("truncated"));

  ASSERT_TRUE(meter->Measure(Ctx()).ok());
  control_.UpdateSerial([](sim::SerialFaults& f) { return f.truncate_next = 1; });
  auto report = meter->TransferSpectrum(Ctx());
  EXPECT_EQ(report.status().code(), StatusCode::kProtocolError);
  EXPECT_THAT(report.status().message(), HasSubstr("of 103 line(s)"));
  ASSERT_TRUE(meter->TransferSpectrum(Ctx()).ok());
}

bool WaitForPath(const std::string& path, std::chrono::milliseconds timeout) {
  const auto end = SteadyClock::now() + timeout;
  while (SteadyClock::now() < end) {
    if (::access(path.c_str(), F_OK) == 0) return true;
    std::this_thread::sleep_for(10ms);
  }
  return false;
}

TEST_F(Pr650DriverTest, PortVanishingMidTransferDisconnectsAndReconnectWorks) {
  auto meter = Configured(100);
  ASSERT_TRUE(meter->Measure(Ctx()).ok());
  control_.UpdateSerial([](sim::SerialFaults& f) { return f.vanish_seconds = 3.0; });  // 0.3 s

  auto report = meter->TransferSpectrum(Ctx());
  ASSERT_FALSE(report.ok());
  EXPECT_EQ(report.status().code(), StatusCode::kDisconnected);
  EXPECT_THAT(report.status().message(), HasSubstr("vanished"));
  EXPECT_FALSE(meter->connected());
  EXPECT_EQ(meter->Measure(Ctx()).status().code(), StatusCode::kDisconnected);

  // While the port is gone, connecting reports it gone (not a misconfigured name).
  Status gone = meter->Connect(Ctx());
  EXPECT_EQ(gone.code(), StatusCode::kDisconnected) << gone.ToString();

  ASSERT_TRUE(WaitForPath(endpoint_->path(), 3s));
  Status back = meter->Connect(Ctx());
  ASSERT_TRUE(back.ok()) << back.ToString();
  // The configured setup is sent again before measuring (the driver cannot know it survived).
  auto outcome = meter->Measure(Ctx());
  ASSERT_TRUE(outcome.ok()) << outcome.status().ToString();
  EXPECT_EQ(outcome->integration_ms, 100);
  auto again = meter->TransferSpectrum(Ctx());
  ASSERT_TRUE(again.ok()) << again.status().ToString();
  ExpectSpectrumOf(*again, backend_.level());
}

// ---- cancellation and deadlines ----------------------------------------------------------------

TEST_F(Pr650DriverTest, CancellingAMeasurementReturnsPromptlyAndTheLateReplyIsDiscarded) {
  sim::Pr650EndpointOptions o = FastEndpointOptions();
  o.time_scale.factor = 1;  // a 2 s measurement really takes 2 s
  o.pace_replies = false;
  StartEndpoint(o);
  auto meter = Configured(100);
  backend_.queue_durations({2.0, 0.05});
  backend_.set_quality(18);  // the first (abandoned) measurement says "018" ...

  CancelToken cancel;
  std::thread canceller([cancel]() mutable {
    std::this_thread::sleep_for(100ms);
    cancel.Cancel("operator pressed stop");
  });
  const auto start = SteadyClock::now();
  auto cancelled = meter->Measure(Ctx(10s, cancel));
  const auto took = SteadyClock::now() - start;
  canceller.join();
  EXPECT_EQ(cancelled.status().code(), StatusCode::kCancelled);
  EXPECT_THAT(cancelled.status().message(), HasSubstr("operator pressed stop"));
  EXPECT_LT(took, 1500ms);  // well before the meter's 2 s measurement ends

  backend_.set_quality(0);  // ... the next one "000"
  auto outcome = meter->Measure(Ctx());
  ASSERT_TRUE(outcome.ok()) << outcome.status().ToString();
  EXPECT_EQ(outcome->quality_code, 0);
  EXPECT_FALSE(outcome->flagged);  // the stale "018" was not taken for this measurement's reply
  EXPECT_TRUE(log_.Contains("discarded a late reply")) << log_.All();
  EXPECT_EQ(backend_.setups().size(), 2u);
}

TEST_F(Pr650DriverTest, DeadlineShorterThanTheMeasurementIsATimeout) {
  sim::Pr650EndpointOptions o = FastEndpointOptions();
  o.time_scale.factor = 1;
  StartEndpoint(o);
  auto meter = Configured(100);
  backend_.queue_durations({1.0});
  const auto start = SteadyClock::now();
  auto outcome = meter->Measure(Ctx(200ms));
  EXPECT_EQ(outcome.status().code(), StatusCode::kTimeout);
  EXPECT_LT(SteadyClock::now() - start, 900ms);
}

}  // namespace
}  // namespace brdf::testing
