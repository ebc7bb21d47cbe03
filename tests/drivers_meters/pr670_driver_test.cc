// The PR-670 driver against brdf-sim's PR-670 endpoint on a real pty: remote mode, identity, the
// setup commands, M5 reports of 201 bands, the result codes through the quality policy, a meter
// that leaves remote mode, a vanishing port, garbage, and one owner per port.
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <algorithm>
#include <memory>

#include "drivers/pr670/spectroradiometer.h"
#include "tests/drivers_meters/meter_test_rig.h"

namespace brdf::testing {
namespace {

using ::testing::HasSubstr;

class Pr670Driver : public MeterDriverTest<sim::Pr670Endpoint, drivers::Pr670Spectroradiometer> {
 protected:
  Pr670Driver() : MeterDriverTest(WavelengthGrid{380, 2, 201}) {}
  void SetUp() override {
    Start(sim::Pr670EndpointOptions{FastLine("\r\n", "67012345"), "PR-670"}, FastPr670);
  }
};

TEST_F(Pr670Driver, EntersRemoteModeIdentifiesAndReadsTwoHundredOneBands) {
  ConnectAndConfigure({200, 2, false});
  EXPECT_TRUE(endpoint_->remote_mode());
  Result<drivers::MeterIdentity> id = meter_->Identify(Ctx());
  ASSERT_TRUE(id.ok()) << id.status().ToString();
  EXPECT_EQ(id->model, "PR-670");
  EXPECT_EQ(id->serial_number, "67012345");
  EXPECT_EQ(id->grid, (WavelengthGrid{380, 2, 201}));

  bool measured_first = false;
  Result<drivers::MeasuredSpectrum> m = meter_->MeasureSpectrum(
      Ctx(), [&](const drivers::MeasurementOutcome& o) { measured_first = o.quality_code == 0; });
  ASSERT_TRUE(m.ok()) << m.status().ToString();
  EXPECT_TRUE(measured_first);
  EXPECT_EQ(m->outcome.quality_code, 0);
  EXPECT_FALSE(m->outcome.flagged);
  ASSERT_EQ(m->report.radiance.size(), 201u);
  const std::vector<double> truth = GridBackend::Spectrum({380, 2, 201}, backend_.level());
  for (std::size_t i = 0; i < truth.size(); ++i) {
    EXPECT_NEAR(m->report.radiance[i], truth[i], truth[i] * 1e-3) << "band " << i;
  }
  // Q before PHOTO; the setup as asked; then the measurement.
  const std::vector<std::string> sent = endpoint_->commands();
  ASSERT_GE(sent.size(), 2u);
  EXPECT_EQ(sent[0], "Q");
  EXPECT_EQ(sent[1], "PHOTO");
  for (const char* c : {"SE200", "SN2", "SS0", "M5", "D111", "D110", "D120"}) {
    EXPECT_TRUE(Sent(sent, c)) << c;
  }
  // TransferSpectrum hands over what M5 brought.
  Result<drivers::SpectrumReport> again = meter_->TransferSpectrum(Ctx());
  ASSERT_TRUE(again.ok());
  EXPECT_EQ(again->radiance, m->report.radiance);
}

TEST_F(Pr670Driver, TooDarkOnALightReadingDoublesTheExposure) {
  ConnectAndConfigure({200, 1, false});
  backend_.queue_qualities({10});  // the simulated meter answers −8
  Result<drivers::MeasurementOutcome> o = meter_->Measure(Ctx());
  ASSERT_TRUE(o.ok()) << o.status().ToString();
  EXPECT_EQ(o->attempts, 2);
  EXPECT_EQ(o->quality_code, 0);
  EXPECT_THAT(o->note, HasSubstr("code -8 (too dark)"));
  EXPECT_THAT(o->note, HasSubstr("doubled from 200 to 400 ms"));
  EXPECT_TRUE(Sent(endpoint_->commands(), "SE400"));
}

TEST_F(Pr670Driver, TooDarkOnADarkReadingIsAcceptedAsZeros) {
  ConnectAndConfigure({200, 1, false, /*dark=*/true});
  backend_.set_quality(10);
  Result<drivers::MeasuredSpectrum> m = meter_->MeasureSpectrum(Ctx(), nullptr);
  ASSERT_TRUE(m.ok()) << m.status().ToString();
  EXPECT_EQ(m->outcome.quality_code, -8);
  EXPECT_FALSE(m->outcome.flagged);
  EXPECT_EQ(m->outcome.attempts, 1);
  ASSERT_EQ(m->report.radiance.size(), 201u);
  EXPECT_TRUE(std::all_of(m->report.radiance.begin(), m->report.radiance.end(),
                          [](double v) { return v == 0.0; }));
}

TEST_F(Pr670Driver, ASyncFailureSwitchesSyncOffAndMeasuresAgain) {
  ConnectAndConfigure({200, 1, /*sync=*/true});
  Fault([](sim::SerialFaults& f) {
    f.quality_code = -1;
    f.quality_count = 1;
  });
  Result<drivers::MeasurementOutcome> o = meter_->Measure(Ctx());
  ASSERT_TRUE(o.ok()) << o.status().ToString();
  EXPECT_EQ(o->attempts, 2);
  EXPECT_THAT(o->note, HasSubstr("light source sync failure"));
  const std::vector<std::string> sent = endpoint_->commands();
  EXPECT_TRUE(Sent(sent, "SS1"));
  EXPECT_TRUE(Sent(sent, "SS0"));
}

TEST_F(Pr670Driver, AnUnknownResultCodeFailsInTheMetersWords) {
  ConnectAndConfigure({200, 1, false});
  Fault([](sim::SerialFaults& f) {
    f.quality_code = -3;
    f.quality_count = 100;
  });
  Result<drivers::MeasurementOutcome> o = meter_->Measure(Ctx());
  ASSERT_EQ(o.status().code(), StatusCode::kDeviceError) << o.status().ToString();
  EXPECT_EQ(o.status().device_code(), -3);
  EXPECT_THAT(o.status().message(), HasSubstr("code -3"));
}

TEST_F(Pr670Driver, AMeterThatLeftRemoteModeTimesOutAndAnsweresOnceConnectedAgain) {
  ConnectAndConfigure({200, 1, false});
  Fault([](sim::SerialFaults& f) { f.leave_remote = true; });
  Result<drivers::MeasurementOutcome> lost = meter_->Measure(Ctx());
  EXPECT_EQ(lost.status().code(), StatusCode::kTimeout) << lost.status().ToString();
  EXPECT_FALSE(endpoint_->remote_mode());
  // What the rig does on a timeout: disconnect; the next use connects (PHOTO) again.
  meter_->Disconnect();
  ConnectAndConfigure({200, 1, false});
  Result<drivers::MeasurementOutcome> back = meter_->Measure(Ctx());
  ASSERT_TRUE(back.ok()) << back.status().ToString();
}

TEST_F(Pr670Driver, AVanishingPortIsADisconnectAndTheMeterComesBack) {
  ConnectAndConfigure({200, 1, false});
  Fault([](sim::SerialFaults& f) { f.vanish_seconds = 5; });  // 50 ms of real time
  Result<drivers::MeasuredSpectrum> gone = meter_->MeasureSpectrum(Ctx(), nullptr);
  EXPECT_EQ(gone.status().code(), StatusCode::kDisconnected) << gone.status().ToString();
  EXPECT_FALSE(meter_->connected());
  std::this_thread::sleep_for(std::chrono::milliseconds(150));
  ConnectAndConfigure({200, 1, false});
  EXPECT_TRUE(meter_->MeasureSpectrum(Ctx(), nullptr).ok());
}

TEST_F(Pr670Driver, GarbageIsAProtocolError) {
  ConnectAndConfigure({200, 1, false});
  Fault([](sim::SerialFaults& f) { f.garbage_next = 1; });
  Result<drivers::MeterIdentity> id = meter_->Identify(Ctx());
  EXPECT_EQ(id.status().code(), StatusCode::kProtocolError) << id.status().ToString();
  EXPECT_THAT(id.status().message(), HasSubstr("D111"));
}

TEST_F(Pr670Driver, DisconnectLeavesRemoteModeAndASecondOwnerIsRefused) {
  ConnectAndConfigure({200, 1, false});
  std::vector<std::string> other_log;
  drivers::Pr670Spectroradiometer second(FastPr670(endpoint_->path(), &other_log));
  Status refused = second.Connect(Ctx());
  EXPECT_EQ(refused.code(), StatusCode::kFailedPrecondition) << refused.ToString();
  EXPECT_THAT(refused.message(), HasSubstr("in use"));
  meter_->Disconnect();
  std::this_thread::sleep_for(std::chrono::milliseconds(50));
  EXPECT_FALSE(endpoint_->remote_mode());
}

TEST(Pr655Driver, APr655ReportsItsOwnGridOfOneHundredOneBands) {
  GridBackend backend(WavelengthGrid::Pr650());
  sim::SimControl control;
  sim::Pr670Endpoint endpoint(backend, control, {FastLine("\r\n", "65500001"), "PR-655"});
  ASSERT_TRUE(endpoint.Start().ok());
  std::vector<std::string> log;
  drivers::Pr670Options options = FastPr670(endpoint.path(), &log);
  options.model = "PR-655";
  drivers::Pr670Spectroradiometer meter(options);
  ASSERT_TRUE(meter.Connect(Ctx()).ok());
  Result<drivers::MeterIdentity> id = meter.Identify(Ctx());
  ASSERT_TRUE(id.ok()) << id.status().ToString();
  EXPECT_EQ(id->model, "PR-655");
  EXPECT_EQ(id->grid, WavelengthGrid::Pr650());
  ASSERT_TRUE(meter.Configure({0, 1, false}, Ctx()).ok());
  Result<drivers::MeasuredSpectrum> m = meter.MeasureSpectrum(Ctx(), nullptr);
  ASSERT_TRUE(m.ok()) << m.status().ToString();
  EXPECT_EQ(m->report.radiance.size(), 101u);
  EXPECT_TRUE(Sent(endpoint.commands(), "SE0"));  // adaptive exposure
}

}  // namespace
}  // namespace brdf::testing
