// The simulated rotation stage: four AZ-like drives (α unit 1, β 2, γ 3, δ 4 — the detector arm,
// which can be left out) and the control unit (100), served over Modbus TCP and Modbus RTU on a
// pty at the same time. Each unit id has its own registers (stage/sim_axis.h); the control unit's
// map is in stage/control_map.h. Also the optics' StagePoseSource: LivePose() is where the axes
// are now, on the simulator's scaled clock.
//
// Injected Modbus faults (SimControl::modbus(), consumed as they fire, axis unit ids only):
// exception 02/04/06 (any code) for the next N requests, replies held back by late_reply_ms for the
// next N requests, a dropped TCP connection, an alarm half-way through the next move, a stall where
// MOVE never clears; the drives' word order swapped (a setting that stays); an outage where the
// drives go away for a while (TCP: connections refused) and come back.
#pragma once

#include <array>
#include <atomic>
#include <chrono>
#include <functional>
#include <memory>
#include <mutex>
#include <span>
#include <string>

#include "core/pose.h"
#include "tools/brdf-sim/sim_shared.h"
#include "tools/brdf-sim/stage/control_map.h"
#include "tools/brdf-sim/stage/control_unit.h"
#include "tools/brdf-sim/stage/dispatch.h"
#include "tools/brdf-sim/stage/rtu_endpoint.h"
#include "tools/brdf-sim/stage/sim_axis.h"
#include "tools/brdf-sim/stage/tcp_endpoint.h"

namespace brdf::sim {

struct StageSimConfig {
  // α, β, γ, δ in that order. Unit ids 1–4 by default; axes[3].present = false leaves out the
  // motorized detector arm.
  std::array<SimAxisConfig, 4> axes = DefaultAxes();
  int control_unit_id = control_map::kDefaultUnitId;
  // What the axis drives answer; any other function code is exception 01 (the control unit
  // answers everything brdf-sim serves).
  FunctionCodes drive_function_codes = *DocumentedFunctionCodes("az");
  TimeScale time_scale;

  bool serve_tcp = true;
  std::string tcp_host = "127.0.0.1";
  int tcp_port = 0;  // 0 = pick a free port (see StageSimulator::tcp_port())
  bool serve_rtu = true;

  static std::array<SimAxisConfig, 4> DefaultAxes();
};

class StageSimulator final : public StagePoseSource, private StageDispatcher {
 public:
  // `power_cycle_meter` is called when the control unit's power-cycle register is written (from
  // an endpoint thread; it may be empty).
  StageSimulator(StageSimConfig config, SimControl& control,
                 std::function<void()> power_cycle_meter = {});
  ~StageSimulator() override;
  StageSimulator(const StageSimulator&) = delete;
  StageSimulator& operator=(const StageSimulator&) = delete;

  // Opens the endpoints. False with `error` set (and nothing left running) on failure.
  bool Start(std::string* error);
  void Shutdown();

  int tcp_port() const { return tcp_.port(); }
  const std::string& rtu_path() const { return rtu_.path(); }
  int control_unit_id() const { return config_.control_unit_id; }
  const StageSimConfig& config() const { return config_; }

  // Where the axes are now, in degrees (absent axes read 0).
  Pose LivePose() const override;
  // One axis (0 α … 3 δ) without going through Modbus; for tests and status output.
  SimAxisSnapshot AxisSnapshot(int index) const;
  // Serves one request as an endpoint would (for tests of the register model without sockets).
  StageReply HandleForTest(std::uint8_t unit, std::span<const std::uint8_t> pdu,
                           StageTransport transport) {
    return Handle(unit, pdu, transport);
  }

 private:
  StageReply Handle(std::uint8_t unit, std::span<const std::uint8_t> pdu,
                    StageTransport transport) override;
  double NowSim() const;

  const StageSimConfig config_;
  SimControl& control_;
  const std::chrono::steady_clock::time_point epoch_;
  StageControlUnit control_unit_;
  // While an injected outage lasts (ModbusFaults::outage_ms): its end, on the steady clock.
  std::atomic<std::chrono::steady_clock::rep> outage_until_{0};
  mutable std::mutex mu_;  // guards the axes
  std::array<std::unique_ptr<SimAxis>, 4> axes_;
  StageTcpEndpoint tcp_{*this};
  StageRtuEndpoint rtu_{*this};
};

}  // namespace brdf::sim
