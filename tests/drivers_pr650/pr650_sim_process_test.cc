// The PR-650 driver against the real brdf-sim process (its PR-650 on a pty, its optics behind it),
// started through tests/support/sim/process.h: the same path the daemon takes in a lab without the
// meter.
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <cmath>

#include "drivers/pr650/spectroradiometer.h"
#include "tests/drivers_pr650/pr650_test_rig.h"
#include "tests/support/sim/process.h"

namespace brdf::testing {
namespace {

using ::testing::HasSubstr;

std::unique_ptr<SimProcess> StartSim(std::vector<std::string> extra) {
  // No wake-up window: how long the process takes to start under load is not what is tested here
  // (the in-process endpoint tests cover the window).
  std::vector<std::string> args = {"--time-scale",  "10", "--modbus-port", "0",
                                   "--wake-window", "0",  "--log-level",   "warn"};
  args.insert(args.end(), extra.begin(), extra.end());
  auto sim = SimProcess::Start(args);
  EXPECT_TRUE(sim.ok()) << sim.status().ToString();
  return sim.ok() ? std::move(sim).value() : nullptr;
}

TEST(Pr650WithBrdfSim, FullCycleThroughTheSimulatorProcess) {
  auto sim = StartSim({});
  ASSERT_NE(sim, nullptr);
  LogCapture log;
  drivers::Pr650Spectroradiometer meter(FastDriverOptions(sim->pr650_path(), log));
  Status s = meter.Connect(Ctx());
  ASSERT_TRUE(s.ok()) << s.ToString();
  auto id = meter.Identify(Ctx());
  ASSERT_TRUE(id.ok()) << id.status().ToString();
  EXPECT_EQ(id->grid, WavelengthGrid::Pr650());
  EXPECT_FALSE(id->serial_number.empty());
  ASSERT_TRUE(meter.Configure({200, 1, false}, Ctx()).ok());
  auto outcome = meter.Measure(Ctx());
  ASSERT_TRUE(outcome.ok()) << outcome.status().ToString();
  auto report = meter.TransferSpectrum(Ctx());
  ASSERT_TRUE(report.ok()) << report.status().ToString();
  ASSERT_EQ(report->radiance.size(), 101u);
  double sum = 0;
  for (double v : report->radiance) {
    EXPECT_TRUE(std::isfinite(v));
    sum += v;
  }
  EXPECT_GT(sum, 0);  // the lamp lights the sample
  EXPECT_EQ(report->quality_code, outcome->quality_code);
}

TEST(Pr650WithBrdfSim, FaultFlagsReachTheDriver) {
  // --pr650-m0-quality: the driver's Measure judges the quality from M0's reply, which the
  // simulator, like the meter, otherwise answers with 000 (the quality is in the reports).
  auto sim = StartSim(
      {"--serial-quality-code", "19", "--serial-quality-count", "1", "--pr650-m0-quality"});
  ASSERT_NE(sim, nullptr);
  LogCapture log;
  drivers::Pr650Spectroradiometer meter(FastDriverOptions(sim->pr650_path(), log));
  ASSERT_TRUE(meter.Connect(Ctx()).ok());
  ASSERT_TRUE(meter.Configure({400, 1, false}, Ctx()).ok());
  auto outcome = meter.Measure(Ctx());
  ASSERT_TRUE(outcome.ok()) << outcome.status().ToString();
  EXPECT_GE(outcome->attempts, 2);
  EXPECT_THAT(outcome->note, HasSubstr("halved from 400 to 200 ms"));
}

TEST(Pr650WithBrdfSim, SilentSimulatorTimesOutWithTheHint) {
  auto sim = StartSim({"--serial-silent"});
  ASSERT_NE(sim, nullptr);
  LogCapture log;
  drivers::Pr650Options options = FastDriverOptions(sim->pr650_path(), log);
  options.wake_attempts = 2;
  drivers::Pr650Spectroradiometer meter(options);
  Status s = meter.Connect(Ctx());
  EXPECT_EQ(s.code(), StatusCode::kTimeout);
  EXPECT_THAT(s.message(), HasSubstr("XFER/CTRLR"));
}

}  // namespace
}  // namespace brdf::testing
