// The register conversation with one drive (one axis): read its status, alarm code and feedback
// position, write an operation block, send home / stop / alarm-reset commands. Translates between
// the profile's registers and degrees; knows nothing of multi-axis moves or waiting.
#pragma once

#include <cstdint>
#include <string>

#include "core/call_context.h"
#include "core/status.h"
#include "drivers/rotation_stage.h"
#include "drivers/stage/modbus_bus.h"
#include "drivers/stage/modbus_codec.h"
#include "drivers/stage/register_profile.h"

namespace brdf::drivers::stage {

struct DriveStatus {
  StatusFlags flags;
  std::uint32_t raw = 0;  // the status word as read
  int alarm_code = 0;     // present alarm code (0 without an alarm or without the register)
};

class AxisIo {
 public:
  // `profile` and `bus` must outlive this object.
  AxisIo(Axis axis, AxisConfig config, const RegisterProfile& profile, ModbusBus& bus);

  Axis axis() const { return axis_; }
  const AxisConfig& config() const { return config_; }
  ModbusBus& bus() const { return bus_; }
  // "axis alpha (unit 1 on Modbus TCP 127.0.0.1:502)", for messages.
  const std::string& name() const { return name_; }

  // Status word and alarm code (one request when the registers are adjacent).
  Result<DriveStatus> ReadStatus(const CallContext& ctx,
                                 BusPriority priority = BusPriority::kNormal) const;
  Result<std::int32_t> ReadFeedbackCounts(const CallContext& ctx) const;
  Result<double> ReadPositionDeg(const CallContext& ctx) const;

  // Writes the operation block for an absolute move to `target_deg` at the configured speed with
  // one FC16 (for kTriggerInBlock this also starts the move); the other trigger styles follow
  // with one write of the trigger value. The caller checks the travel limits first.
  Status StartMove(double target_deg, const CallContext& ctx) const;

  // Asserts (`on`) or releases a command. kPulseBits writes the bits to the input command register
  // (on) or 0 (off); kWriteValue writes its value when `on` and does nothing when released.
  // kFailedPrecondition for kNone.
  Status SetCommand(const CommandAction& command, const char* command_name, bool on,
                    const CallContext& ctx, BusPriority priority = BusPriority::kNormal) const;

  double CountsToDeg(std::int32_t counts) const;

 private:
  Result<std::vector<std::uint16_t>> Read(const RegisterField& field, const CallContext& ctx,
                                          BusPriority priority, const char* what) const;

  Axis axis_;
  AxisConfig config_;
  const RegisterProfile& profile_;
  ModbusBus& bus_;
  std::string name_;
};

}  // namespace brdf::drivers::stage
