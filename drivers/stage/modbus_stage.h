// The α/β/γ(/δ) stage on Modbus drives: a RotationStage built from a register profile, per-axis
// settings and one or more buses (each with its own owner thread, see modbus_bus.h).
//
// A move: check every target against its travel limits (kInvalidArgument, before anything
// moves); refuse to start while any named axis has an alarm (kFailedPrecondition, reset first);
// write each axis's operation block with one FC16 so all axes start together; then poll every
// axis's status every poll_interval until MOVE is clear and IN-POS is set and the feedback is at
// the target. An alarm is a kDeviceError carrying the alarm code; an axis that does not arrive
// within distance ÷ speed + move_margin is a kTimeout naming it; a cancelled call returns
// kCancelled. In all three cases the other axes are stopped first.
//
// All waiting (polling, pulse hold, move timeouts) runs on ctx.clock(), so tests drive the stage on
// scaled time; libmodbus's own response timeout is real time.
#pragma once

#include <array>
#include <atomic>
#include <chrono>
#include <memory>
#include <optional>
#include <vector>

#include "core/call_context.h"
#include "core/clock.h"
#include "core/status.h"
#include "drivers/rotation_stage.h"
#include "drivers/stage/axis_io.h"
#include "drivers/stage/modbus_bus.h"
#include "drivers/stage/register_profile.h"

namespace brdf::drivers::stage {

struct ModbusStageConfig {
  RegisterProfile profile = RegisterProfile::AzDefault();
  std::vector<BusConfig> buses;    // at least one; AxisConfig::bus indexes it
  std::array<AxisConfig, 4> axes;  // indexed by Axis; alpha and beta must be present

  Clock::Duration poll_interval = std::chrono::milliseconds(100);
  // How long a level command (STOP, ZHOME, ALM-RST) stays set before it is cleared.
  Clock::Duration pulse_hold = std::chrono::milliseconds(20);
  // Added to distance ÷ speed for each axis's move timeout (acceleration, settling).
  Clock::Duration move_margin = std::chrono::seconds(2);
  // A drive may report the previous move's IN-POS for this long after a trigger before MOVE rises.
  Clock::Duration start_grace = std::chrono::milliseconds(500);
  // The feedback must end this close to the target (at least one count of every axis).
  double position_tolerance_deg = 0.05;
  // Deadline of the stop sent after a failure or a cancellation.
  Clock::Duration stop_timeout = std::chrono::seconds(2);
};

// kConfigurationError naming the field (profile, buses, axes, timings).
Status ValidateStageConfig(const ModbusStageConfig& config);

class ModbusStage final : public RotationStage {
 public:
  // Validates the configuration; nothing is opened until Connect.
  static Result<std::unique_ptr<ModbusStage>> Create(ModbusStageConfig config);
  ~ModbusStage() override;

  // Opens every bus and reads every present axis's status once (a wrong unit id or register map
  // fails here, not at the first move). Idempotent when connected.
  Status Connect(const CallContext& ctx) override;
  void Disconnect() override;
  bool connected() const override { return connected_.load(); }
  bool HasAxis(Axis axis) const override;

  Status MoveTo(const StageTarget& target, const CallContext& ctx) override;
  Result<AxisState> ReadAxis(Axis axis, const CallContext& ctx) override;
  Result<Pose> ReadPose(const CallContext& ctx) override;
  // Pulses ALM-RST (set, hold, clear) and checks that the alarm is gone.
  Status ResetAlarm(Axis axis, const CallContext& ctx) override;
  // Pulses ZHOME and waits until the axis is home (timeout: full travel ÷ speed + margin).
  Status Home(Axis axis, const CallContext& ctx) override;
  // Sets STOP on every present axis, then clears it. Honours ctx's deadline but not its
  // cancellation: a stop must go out even when the abort that asked for it cancelled the token.
  Status Stop(const CallContext& ctx) override;

  const ModbusStageConfig& config() const { return config_; }

 private:
  // One axis being waited for.
  struct Motion {
    const AxisIo* io = nullptr;
    std::optional<double> target_deg;  // empty for homing
    Clock::TimePoint started;
    Clock::TimePoint timeout_at;
    double expected_s = 0;  // distance ÷ speed, for messages
    bool done = false;
  };

  explicit ModbusStage(ModbusStageConfig config);

  const AxisIo* IoFor(Axis axis) const { return axes_[static_cast<int>(axis)].get(); }
  Status RequireConnected(const char* what) const;
  Status CheckNoAlarm(const AxisIo& io, const CallContext& ctx) const;
  Status PulseCommand(const std::vector<const AxisIo*>& axes, const CommandAction& command,
                      const char* command_name, const CallContext& ctx, BusPriority priority);
  Status WaitForMotion(std::vector<Motion>& motions, const CallContext& ctx, const char* what);
  // One poll of a motion not yet done: its status, alarm, arrival and time limit. Ok when it is
  // done or still under way; gave_up when the call was cancelled or ran out of time meanwhile
  // (WaitForMotion's checks report it). `all`: the axes to stop after a failure.
  Status PollMotion(Motion& m, const std::vector<const AxisIo*>& all, const CallContext& ctx,
                    const char* what, bool& gave_up);
  // The drive says the move is complete: homing counts once the start grace has passed; a move
  // once the axis is within tolerance of its target (stopped short: an error).
  Status CheckArrival(Motion& m, Clock::TimePoint now, const std::vector<const AxisIo*>& all,
                      const CallContext& ctx, const char* what, bool& gave_up);
  // Best-effort stop of `axes` on a fresh, uncancelled context; returns "" or a note for messages.
  std::string StopAfterFailure(const std::vector<const AxisIo*>& axes, const Clock& clock);
  // Rejects a second MoveTo/Home while one is running.
  class MotionGuard;

  ModbusStageConfig config_;
  std::vector<std::unique_ptr<ModbusBus>> buses_;
  std::array<std::unique_ptr<AxisIo>, 4> axes_;  // null for absent axes
  std::atomic<bool> connected_{false};
  std::atomic<bool> in_motion_{false};
};

}  // namespace brdf::drivers::stage
