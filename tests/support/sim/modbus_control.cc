#include "tests/support/sim/modbus_control.h"

#include <modbus.h>

#include <cerrno>
#include <cmath>

#include "tools/brdf-sim/stage/control_map.h"

namespace brdf::testing {
namespace {

namespace map = sim::control_map;

// The simulated drives' feedback position register (tools/brdf-sim/stage/sim_axis.h).
constexpr std::uint16_t kFeedbackPosition = 0x00CC;

std::uint16_t Word(int value) {
  return static_cast<std::uint16_t>(value);
}
std::uint16_t Flag(bool value) {
  return value ? 1 : 0;
}

}  // namespace

Result<std::unique_ptr<ModbusControl>> ModbusControl::Connect(
    const std::string& host, int port, int unit, std::chrono::milliseconds response_timeout) {
  const std::string where = host + ":" + std::to_string(port) + " unit " + std::to_string(unit);
  modbus_t* ctx = modbus_new_tcp(host.c_str(), port);
  if (ctx == nullptr) {
    return InvalidArgument("cannot create a Modbus TCP context for " + where + ": " +
                           modbus_strerror(errno));
  }
  const auto ms = response_timeout.count();
  modbus_set_response_timeout(ctx, static_cast<std::uint32_t>(ms / 1000),
                              static_cast<std::uint32_t>(ms % 1000) * 1000);
  if (modbus_set_slave(ctx, unit) != 0 || modbus_connect(ctx) != 0) {
    const std::string err = modbus_strerror(errno);
    modbus_free(ctx);
    return Disconnected("cannot connect to brdf-sim's Modbus server at " + where + ": " + err +
                        "; is brdf-sim running, and is that the port it printed?");
  }
  return std::unique_ptr<ModbusControl>(new ModbusControl(ctx, unit, where));
}

ModbusControl::ModbusControl(modbus_t* ctx, int unit, std::string where)
    : ctx_(ctx), unit_(unit), where_(std::move(where)) {}

ModbusControl::~ModbusControl() {
  modbus_close(ctx_);
  modbus_free(ctx_);
}

Status ModbusControl::Error(const std::string& what) const {
  const int err = errno;
  const std::string message = what + " on " + where_ + ": " + modbus_strerror(err);
  if (err > MODBUS_ENOBASE && err < MODBUS_ENOBASE + 0x100) {
    return DeviceError(err - MODBUS_ENOBASE, message);
  }
  return Disconnected(message);
}

Status ModbusControl::WriteRegisters(std::uint16_t address, std::span<const std::uint16_t> values) {
  if (modbus_set_slave(ctx_, unit_) != 0 ||
      modbus_write_registers(ctx_, address, static_cast<int>(values.size()), values.data()) !=
          static_cast<int>(values.size())) {
    return Error("writing " + std::to_string(values.size()) + " register(s) at " +
                 std::to_string(address));
  }
  return Status::Ok();
}

Result<std::vector<std::uint16_t>> ModbusControl::ReadFrom(int unit, std::uint16_t address,
                                                           int count) {
  std::vector<std::uint16_t> out(static_cast<std::size_t>(count));
  if (modbus_set_slave(ctx_, unit) != 0 ||
      modbus_read_registers(ctx_, address, count, out.data()) != count) {
    return Error("reading " + std::to_string(count) + " register(s) at " + std::to_string(address) +
                 " of unit " + std::to_string(unit));
  }
  return out;
}

Result<std::vector<std::uint16_t>> ModbusControl::ReadRegisters(std::uint16_t address, int count) {
  return ReadFrom(unit_, address, count);
}

Status ModbusControl::SetMounted(sim::MountedTarget target) {
  const std::uint16_t v = Word(static_cast<int>(target));
  return WriteRegisters(map::kMountedTarget, std::span(&v, 1));
}

Result<sim::MountedTarget> ModbusControl::Mounted() {
  BRDF_ASSIGN_OR_RETURN(auto r, ReadRegisters(map::kMountedTarget, 1));
  return static_cast<sim::MountedTarget>(r[0]);
}

Status ModbusControl::PowerCycleMeter() {
  const std::uint16_t v = 1;
  return WriteRegisters(map::kPowerCycleMeter, std::span(&v, 1));
}

Status ModbusControl::SetSerialFaults(const sim::SerialFaults& f) {
  const auto vanish_ms = static_cast<std::uint32_t>(std::llround(f.vanish_seconds * 1000.0));
  const std::uint16_t regs[] = {
      Flag(f.silent),
      Word(f.garbage_next),
      Word(f.truncate_next),
      static_cast<std::uint16_t>(static_cast<std::int16_t>(f.quality_code)),
      Word(f.quality_count),
      static_cast<std::uint16_t>(vanish_ms >> 16),
      static_cast<std::uint16_t>(vanish_ms & 0xFFFFu),
      Word(f.no_data_next),
      Word(f.units_code),
      Flag(f.leave_remote),
  };
  static_assert(map::kSerialVanishMs - map::kSerialSilent == 5, "serial fault block layout");
  static_assert(map::kSerialLeaveRemote - map::kSerialSilent == 9, "serial fault block layout");
  return WriteRegisters(map::kSerialSilent, regs);
}

Status ModbusControl::SetModbusFaults(const sim::ModbusFaults& f) {
  const std::uint16_t regs[] = {
      Word(f.exception_code), Word(f.exception_count), Word(f.late_reply_ms),
      Word(f.late_count),     Flag(f.drop_connection), Flag(f.alarm_mid_move),
      Flag(f.stall),          Flag(f.swap_word_order), Word(f.outage_ms),
  };
  static_assert(map::kModbusOutageMs - map::kModbusExceptionCode == 8, "Modbus fault block layout");
  return WriteRegisters(map::kModbusExceptionCode, regs);
}

Result<sim::SerialFaults> ModbusControl::SerialFaults() {
  BRDF_ASSIGN_OR_RETURN(const auto v, ReadRegisters(map::kSerialSilent, 10));
  sim::SerialFaults f;
  f.silent = v[0] != 0;
  f.garbage_next = v[1];
  f.truncate_next = v[2];
  f.quality_code = static_cast<std::int16_t>(v[3]);
  f.quality_count = v[4];
  f.vanish_seconds = ((static_cast<std::uint32_t>(v[5]) << 16) | v[6]) / 1000.0;
  f.no_data_next = v[7];
  f.units_code = v[8];
  f.leave_remote = v[9] != 0;
  return f;
}

Result<sim::ModbusFaults> ModbusControl::ModbusFaults() {
  BRDF_ASSIGN_OR_RETURN(const auto v, ReadRegisters(map::kModbusExceptionCode, 9));
  sim::ModbusFaults f;
  f.exception_code = v[0];
  f.exception_count = v[1];
  f.late_reply_ms = v[2];
  f.late_count = v[3];
  f.drop_connection = v[4] != 0;
  f.alarm_mid_move = v[5] != 0;
  f.stall = v[6] != 0;
  f.swap_word_order = v[7] != 0;
  f.outage_ms = v[8];
  return f;
}

Result<std::int32_t> ModbusControl::AxisCounts(int axis_unit) {
  BRDF_ASSIGN_OR_RETURN(auto r, ReadFrom(axis_unit, kFeedbackPosition, 2));
  // High word first; unpacked by hand (libmodbus 3.1.6's macro shifts without a cast).
  const std::uint32_t raw = (static_cast<std::uint32_t>(r[0]) << 16) | r[1];
  return static_cast<std::int32_t>(raw);
}

Result<double> ModbusControl::AxisDegrees(int axis_unit, double counts_per_degree) {
  BRDF_ASSIGN_OR_RETURN(auto counts, AxisCounts(axis_unit));
  return counts / counts_per_degree;
}

}  // namespace brdf::testing
