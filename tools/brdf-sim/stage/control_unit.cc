#include "tools/brdf-sim/stage/control_unit.h"

#include <algorithm>
#include <cmath>
#include <utility>

#include "tools/brdf-sim/stage/control_map.h"

namespace brdf::sim {

namespace {

namespace cm = control_map;

bool Defined(std::uint16_t a) {
  return a == cm::kMountedTarget || a == cm::kPowerCycleMeter ||
         (a >= cm::kSerialSilent && a <= cm::kSerialLeaveRemote) ||
         (a >= cm::kModbusExceptionCode && a <= cm::kModbusOutageMs) ||
         (a >= cm::kPlacedByHand && a <= cm::kPlacedPhiO);
}

bool IsFlag(std::uint16_t a) {
  return a == cm::kSerialSilent || a == cm::kSerialLeaveRemote || a == cm::kModbusDropConnection ||
         a == cm::kModbusAlarmMidMove || a == cm::kModbusStall || a == cm::kModbusSwapWordOrder ||
         a == cm::kPlacedByHand;
}

std::uint16_t Clamp16(long v) {
  return static_cast<std::uint16_t>(std::clamp<long>(v, 0, 0xFFFF));
}

// The control registers as one image, from the current SimControl state.
std::vector<std::uint16_t> Snapshot(const SimControl& control) {
  std::vector<std::uint16_t> r(cm::kRegisterCount, 0);
  const SerialFaults s = control.serial();
  const ModbusFaults m = control.modbus();
  r[cm::kMountedTarget] = static_cast<std::uint16_t>(control.mounted());
  r[cm::kSerialSilent] = s.silent ? 1 : 0;
  r[cm::kSerialGarbageNext] = Clamp16(s.garbage_next);
  r[cm::kSerialTruncateNext] = Clamp16(s.truncate_next);
  // Signed: two's complement in the register.
  r[cm::kSerialQualityCode] = static_cast<std::uint16_t>(
      static_cast<std::int16_t>(std::clamp(s.quality_code, -32768, 32767)));
  r[cm::kSerialQualityCount] = Clamp16(s.quality_count);
  const auto vanish_ms = static_cast<std::uint32_t>(
      std::clamp(std::llround(s.vanish_seconds * 1000.0), 0LL, 0xFFFFFFFFLL));
  r[cm::kSerialVanishMs] = static_cast<std::uint16_t>(vanish_ms >> 16);
  r[cm::kSerialVanishMs + 1] = static_cast<std::uint16_t>(vanish_ms & 0xFFFF);
  r[cm::kSerialNoDataNext] = Clamp16(s.no_data_next);
  r[cm::kSerialUnitsCode] = Clamp16(s.units_code);
  r[cm::kSerialLeaveRemote] = s.leave_remote ? 1 : 0;
  r[cm::kModbusExceptionCode] = Clamp16(m.exception_code);
  r[cm::kModbusExceptionCount] = Clamp16(m.exception_count);
  r[cm::kModbusLateReplyMs] = Clamp16(m.late_reply_ms);
  r[cm::kModbusLateCount] = Clamp16(m.late_count);
  r[cm::kModbusDropConnection] = m.drop_connection ? 1 : 0;
  r[cm::kModbusAlarmMidMove] = m.alarm_mid_move ? 1 : 0;
  r[cm::kModbusStall] = m.stall ? 1 : 0;
  r[cm::kModbusSwapWordOrder] = m.swap_word_order ? 1 : 0;
  r[cm::kModbusOutageMs] = Clamp16(m.outage_ms);
  const Directions d = control.placed();
  r[cm::kPlacedByHand] = control.by_hand() ? 1 : 0;
  r[cm::kPlacedThetaI] = cm::ToCentidegrees(d.theta_i);
  r[cm::kPlacedThetaI + 1] = cm::ToCentidegrees(d.phi_i);
  r[cm::kPlacedThetaI + 2] = cm::ToCentidegrees(d.theta_o);
  r[cm::kPlacedPhiO] = cm::ToCentidegrees(d.phi_o);
  return r;
}

}  // namespace

StageControlUnit::StageControlUnit(SimControl& control, std::function<void()> power_cycle_meter)
    : control_(control), power_cycle_meter_(std::move(power_cycle_meter)) {}

std::uint8_t StageControlUnit::ReadRegisters(std::uint16_t address, std::uint16_t count,
                                             std::vector<std::uint16_t>& out) {
  if (address + count > cm::kRegisterCount) return modbus::kIllegalDataAddress;
  const auto image = Snapshot(control_);
  out.assign(image.begin() + address, image.begin() + address + count);
  return 0;
}

std::uint8_t StageControlUnit::WriteRegisters(std::uint16_t address,
                                              std::span<const std::uint16_t> values) {
  if (address + values.size() > cm::kRegisterCount) return modbus::kIllegalDataAddress;
  // Validate the whole write before applying any of it.
  for (std::size_t i = 0; i < values.size(); ++i) {
    const auto a = static_cast<std::uint16_t>(address + i);
    const std::uint16_t v = values[i];
    if (!Defined(a)) return modbus::kIllegalDataAddress;
    if (a == cm::kMountedTarget && v > 2) return modbus::kIllegalDataValue;
    if (a == cm::kPowerCycleMeter && v > 1) return modbus::kIllegalDataValue;
    if (IsFlag(a) && v > 1) return modbus::kIllegalDataValue;
    if (a == cm::kModbusExceptionCode && v > 0x0B) return modbus::kIllegalDataValue;
    if (a == cm::kSerialUnitsCode && v > 2) return modbus::kIllegalDataValue;
    if (a >= cm::kPlacedThetaI && a <= cm::kPlacedPhiO &&
        !cm::PlacedAngleInRange(a, cm::FromCentidegrees(v))) {
      return modbus::kIllegalDataValue;
    }
  }
  auto image = Snapshot(control_);
  for (std::size_t i = 0; i < values.size(); ++i) image[address + i] = values[i];
  auto written = [&](std::uint16_t a) { return a >= address && a < address + values.size(); };

  if (written(cm::kMountedTarget)) {
    control_.set_mounted(static_cast<MountedTarget>(image[cm::kMountedTarget]));
  }
  if (address <= cm::kSerialLeaveRemote && address + values.size() > cm::kSerialSilent) {
    control_.UpdateSerial([&](SerialFaults& s) {
      if (written(cm::kSerialSilent)) s.silent = image[cm::kSerialSilent] != 0;
      if (written(cm::kSerialGarbageNext)) s.garbage_next = image[cm::kSerialGarbageNext];
      if (written(cm::kSerialTruncateNext)) s.truncate_next = image[cm::kSerialTruncateNext];
      if (written(cm::kSerialQualityCode)) {
        s.quality_code = static_cast<std::int16_t>(image[cm::kSerialQualityCode]);
      }
      if (written(cm::kSerialQualityCount)) s.quality_count = image[cm::kSerialQualityCount];
      if (written(cm::kSerialVanishMs) || written(cm::kSerialVanishMs + 1)) {
        const std::uint32_t ms = (static_cast<std::uint32_t>(image[cm::kSerialVanishMs]) << 16) |
                                 image[cm::kSerialVanishMs + 1];
        s.vanish_seconds = ms / 1000.0;
      }
      if (written(cm::kSerialNoDataNext)) s.no_data_next = image[cm::kSerialNoDataNext];
      if (written(cm::kSerialUnitsCode)) s.units_code = image[cm::kSerialUnitsCode];
      if (written(cm::kSerialLeaveRemote)) s.leave_remote = image[cm::kSerialLeaveRemote] != 0;
    });
  }
  if (address <= cm::kModbusOutageMs && address + values.size() > cm::kModbusExceptionCode) {
    control_.UpdateModbus([&](ModbusFaults& m) {
      if (written(cm::kModbusExceptionCode)) m.exception_code = image[cm::kModbusExceptionCode];
      if (written(cm::kModbusExceptionCount)) m.exception_count = image[cm::kModbusExceptionCount];
      if (written(cm::kModbusLateReplyMs)) m.late_reply_ms = image[cm::kModbusLateReplyMs];
      if (written(cm::kModbusLateCount)) m.late_count = image[cm::kModbusLateCount];
      if (written(cm::kModbusDropConnection)) {
        m.drop_connection = image[cm::kModbusDropConnection] != 0;
      }
      if (written(cm::kModbusAlarmMidMove)) m.alarm_mid_move = image[cm::kModbusAlarmMidMove] != 0;
      if (written(cm::kModbusStall)) m.stall = image[cm::kModbusStall] != 0;
      if (written(cm::kModbusSwapWordOrder)) {
        m.swap_word_order = image[cm::kModbusSwapWordOrder] != 0;
      }
      if (written(cm::kModbusOutageMs)) m.outage_ms = image[cm::kModbusOutageMs];
    });
  }
  if (address + values.size() > cm::kPlacedByHand) {
    control_.set_placed(image[cm::kPlacedByHand] != 0,
                        Directions{cm::FromCentidegrees(image[cm::kPlacedThetaI]),
                                   cm::FromCentidegrees(image[cm::kPlacedThetaI + 1]),
                                   cm::FromCentidegrees(image[cm::kPlacedThetaI + 2]),
                                   cm::FromCentidegrees(image[cm::kPlacedPhiO])});
  }
  if (written(cm::kPowerCycleMeter) && image[cm::kPowerCycleMeter] == 1 && power_cycle_meter_) {
    power_cycle_meter_();
  }
  return 0;
}

}  // namespace brdf::sim
