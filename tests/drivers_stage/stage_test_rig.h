// The stage simulator and the Modbus stage driver wired together in one test process: the
// simulator serves real Modbus TCP on 127.0.0.1 (port 0) and RTU on a pty; the driver talks to
// it through libmodbus. Both run on the same scaled time (TimeScale / ScaledClock), so a 90° move
// at 30°/s takes 3 simulated seconds and 300 real ms.
#pragma once

#include <gtest/gtest.h>

#include <chrono>
#include <memory>
#include <string>

#include "drivers/stage/modbus_stage.h"
#include "tests/drivers_stage/scaled_clock.h"
#include "tools/brdf-sim/stage/simulator.h"

namespace brdf::testing {

inline constexpr double kTimeScale = 10.0;
inline constexpr double kSpeedDegS = 30.0;

enum class Link { kTcp, kRtu };

inline sim::StageSimConfig DefaultSimConfig() {
  sim::StageSimConfig c;
  c.time_scale.factor = kTimeScale;
  return c;
}

class StageRig {
 public:
  StageRig() : clock_(kTimeScale) {}
  ~StageRig() {
    if (stage_) stage_->Disconnect();
    if (sim_) sim_->Shutdown();
  }

  // Starts the simulator (replacing a running one); ASSERT_TRUE(rig.StartSim()).
  ::testing::AssertionResult StartSim(sim::StageSimConfig config = DefaultSimConfig()) {
    sim_.reset();
    sim_ = std::make_unique<sim::StageSimulator>(std::move(config), control_);
    std::string error;
    if (!sim_->Start(&error)) return ::testing::AssertionFailure() << error;
    return ::testing::AssertionSuccess();
  }

  drivers::stage::BusConfig Bus(Link link) const {
    drivers::stage::BusConfig bus;
    if (link == Link::kTcp) {
      bus.endpoint = drivers::stage::TcpEndpoint{"127.0.0.1", sim_->tcp_port()};
    } else {
      bus.endpoint = drivers::stage::RtuEndpoint{sim_->rtu_path(), 115200, 'E', 8, 1};
    }
    bus.response_timeout = std::chrono::milliseconds(200);
    bus.reconnect_backoff = std::chrono::milliseconds(10);
    bus.busy_backoff = std::chrono::milliseconds(5);
    bus.busy_window = std::chrono::milliseconds(300);
    bus.rtu_drain = std::chrono::milliseconds(200);
    return bus;
  }

  // A driver configuration that mirrors the simulator's axes, all on one bus.
  drivers::stage::ModbusStageConfig DriverConfig(Link link) const {
    drivers::stage::ModbusStageConfig c;
    c.buses = {Bus(link)};
    for (std::size_t i = 0; i < 4; ++i) {
      const sim::SimAxisConfig& s = sim_->config().axes[i];
      drivers::stage::AxisConfig& a = c.axes[i];
      a.present = s.present;
      a.bus = 0;
      a.unit_id = s.unit_id;
      a.counts_per_degree = s.counts_per_degree;
      a.zero_offset_counts = s.zero_offset_counts;
      a.min_deg = s.min_deg;
      a.max_deg = s.max_deg;
      a.speed_deg_s = kSpeedDegS;
    }
    c.move_margin = std::chrono::seconds(3);
    return c;
  }

  ::testing::AssertionResult Connect(drivers::stage::ModbusStageConfig config) {
    auto stage = drivers::stage::ModbusStage::Create(std::move(config));
    if (!stage.ok()) return ::testing::AssertionFailure() << stage.status().ToString();
    stage_ = std::move(*stage);
    const Status st = stage_->Connect(Ctx());
    if (!st.ok()) return ::testing::AssertionFailure() << st.ToString();
    return ::testing::AssertionSuccess();
  }
  ::testing::AssertionResult Connect(Link link) { return Connect(DriverConfig(link)); }

  // A context on the scaled clock: `sim_seconds` of simulated time.
  CallContext Ctx(double sim_seconds = 120, CancelToken cancel = CancelToken()) const {
    return CallContext::WithTimeout(
        std::chrono::duration_cast<Clock::Duration>(std::chrono::duration<double>(sim_seconds)),
        std::move(cancel), clock_);
  }

  double SimSecondsSince(Clock::TimePoint t) const {
    return std::chrono::duration<double>(clock_.Now() - t).count();
  }

  sim::SimControl& control() { return control_; }
  sim::StageSimulator& sim() { return *sim_; }
  drivers::stage::ModbusStage& stage() { return *stage_; }
  const ScaledClock& clock() const { return clock_; }

 private:
  sim::SimControl control_;
  ScaledClock clock_;
  std::unique_ptr<sim::StageSimulator> sim_;
  std::unique_ptr<drivers::stage::ModbusStage> stage_;
};

}  // namespace brdf::testing
