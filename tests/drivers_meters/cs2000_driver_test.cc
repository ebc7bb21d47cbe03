// The CS-2000 driver against brdf-sim's CS-2000 endpoint on a real pty: remote mode, identity,
// speed and sync modes, MEAS,1's two replies, the four spectral blocks (401 values), ERxx codes
// through the quality policy, a meter that leaves remote mode, a vanishing port.
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <memory>
#include <thread>

#include "drivers/cs2000/spectroradiometer.h"
#include "tests/drivers_meters/meter_test_rig.h"

namespace brdf::testing {
namespace {

using ::testing::HasSubstr;

class Cs2000Driver : public MeterDriverTest<sim::Cs2000Endpoint, drivers::Cs2000Spectroradiometer> {
 protected:
  Cs2000Driver() : MeterDriverTest(WavelengthGrid{380, 1, 401}) {}
  void SetUp() override {
    Start(sim::Cs2000EndpointOptions{FastLine("\n", "20001234"), "CS-2000"}, FastCs2000);
  }
};

TEST_F(Cs2000Driver, RemoteModeIdentityAndFourHundredOneValuesInFourBlocks) {
  ConnectAndConfigure({200, 1, false});
  Result<drivers::MeterIdentity> id = meter_->Identify(Ctx());
  ASSERT_TRUE(id.ok()) << id.status().ToString();
  EXPECT_EQ(id->model, "CS-2000");
  EXPECT_EQ(id->serial_number, "20001234");
  EXPECT_EQ(id->grid, (WavelengthGrid{380, 1, 401}));

  bool measured_first = false;
  Result<drivers::MeasuredSpectrum> m = meter_->MeasureSpectrum(
      Ctx(), [&](const drivers::MeasurementOutcome&) { measured_first = true; });
  ASSERT_TRUE(m.ok()) << m.status().ToString();
  EXPECT_TRUE(measured_first);
  EXPECT_EQ(m->outcome.quality_code, 0);
  EXPECT_EQ(m->outcome.integration_ms, 200);
  ASSERT_EQ(m->report.radiance.size(), 401u);
  const std::vector<double> truth = GridBackend::Spectrum({380, 1, 401}, backend_.level());
  for (std::size_t i = 0; i < truth.size(); ++i) {
    EXPECT_NEAR(m->report.radiance[i], truth[i], truth[i] * 1e-4) << "value " << i;
  }
  const std::vector<std::string> sent = endpoint_->commands();
  for (const char* c : {"RMTS,1", "SPMS,3,000200000,2", "SCMS,0", "MEAS,1", "MEDR,1,0,1",
                        "MEDR,1,0,2", "MEDR,1,0,3", "MEDR,1,0,4", "IDDR"}) {
    EXPECT_TRUE(Sent(sent, c)) << c;
  }
}

TEST_F(Cs2000Driver, AnAdaptivePlanLetsTheMeterChooseAndAveragesAreRefused) {
  ConnectAndConfigure({0, 1, true});
  EXPECT_TRUE(Sent(endpoint_->commands(), "SPMS,0,2"));
  EXPECT_TRUE(Sent(endpoint_->commands(), "SCMS,1,10000"));
  Status averaged = meter_->Configure({200, 4, false}, Ctx());
  EXPECT_EQ(averaged.code(), StatusCode::kInvalidArgument);
  EXPECT_THAT(averaged.message(), HasSubstr("no averaging"));
}

TEST_F(Cs2000Driver, OverTheRangeHalvesTheManualIntegration) {
  ConnectAndConfigure({400, 1, false});
  Fault([](sim::SerialFaults& f) {
    f.quality_code = 10;
    f.quality_count = 1;
  });
  Result<drivers::MeasurementOutcome> o = meter_->Measure(Ctx());
  ASSERT_TRUE(o.ok()) << o.status().ToString();
  EXPECT_EQ(o->attempts, 2);
  EXPECT_THAT(o->note, HasSubstr("ER10 (over measurement range)"));
  EXPECT_THAT(o->note, HasSubstr("halved from 400 to 200 ms"));
  EXPECT_TRUE(Sent(endpoint_->commands(), "SPMS,3,000200000,2"));
  EXPECT_TRUE(meter_->TransferSpectrum(Ctx()).ok());
}

TEST_F(Cs2000Driver, AFailingCodeIsADeviceErrorInTheMetersWords) {
  ConnectAndConfigure({200, 1, false});
  Fault([](sim::SerialFaults& f) {
    f.quality_code = 83;
    f.quality_count = 100;
  });
  Result<drivers::MeasurementOutcome> o = meter_->Measure(Ctx());
  ASSERT_EQ(o.status().code(), StatusCode::kDeviceError) << o.status().ToString();
  EXPECT_EQ(o.status().device_code(), 83);
  EXPECT_THAT(o.status().message(), HasSubstr("measurement angle abnormality"));
  EXPECT_EQ(meter_->TransferSpectrum(Ctx()).status().code(), StatusCode::kFailedPrecondition);
}

TEST_F(Cs2000Driver, AMeterThatLeftRemoteModeTimesOutAndAnswersOnceConnectedAgain) {
  ConnectAndConfigure({200, 1, false});
  Fault([](sim::SerialFaults& f) { f.leave_remote = true; });
  Result<drivers::MeasurementOutcome> lost = meter_->Measure(Ctx());
  EXPECT_EQ(lost.status().code(), StatusCode::kTimeout) << lost.status().ToString();
  meter_->Disconnect();
  ConnectAndConfigure({200, 1, false});
  EXPECT_TRUE(meter_->Measure(Ctx()).ok());
}

TEST_F(Cs2000Driver, AVanishingPortDuringTheSpectrumIsADisconnect) {
  ConnectAndConfigure({200, 1, false});
  ASSERT_TRUE(meter_->Measure(Ctx()).ok());
  Fault([](sim::SerialFaults& f) { f.vanish_seconds = 5; });
  Result<drivers::SpectrumReport> gone = meter_->TransferSpectrum(Ctx());
  EXPECT_EQ(gone.status().code(), StatusCode::kDisconnected) << gone.status().ToString();
  EXPECT_FALSE(meter_->connected());
  std::this_thread::sleep_for(std::chrono::milliseconds(150));
  ConnectAndConfigure({200, 1, false});
  ASSERT_TRUE(meter_->Measure(Ctx()).ok());
  EXPECT_TRUE(meter_->TransferSpectrum(Ctx()).ok());
}

TEST_F(Cs2000Driver, ASilentMeterIsAskedRemoteModeAsOftenAsConfiguredThenTimesOut) {
  Fault([](sim::SerialFaults& f) { f.silent = true; });
  Status connected = meter_->Connect(Ctx());
  EXPECT_EQ(connected.code(), StatusCode::kTimeout) << connected.ToString();
  EXPECT_THAT(connected.message(), HasSubstr("did not answer RMTS,1 in 2 attempt(s)"));
  int asked = 0;
  for (const std::string& c : endpoint_->commands()) asked += c == "RMTS,1" ? 1 : 0;
  EXPECT_EQ(asked, 2);  // remote_attempts' default
  EXPECT_FALSE(meter_->connected());
}

TEST_F(Cs2000Driver, DisconnectSwitchesRemoteModeOff) {
  ConnectAndConfigure({200, 1, false});
  meter_->Disconnect();
  EXPECT_TRUE(Sent(endpoint_->commands(), "RMTS,0"));
  EXPECT_FALSE(endpoint_->remote_mode());
}

}  // namespace
}  // namespace brdf::testing
