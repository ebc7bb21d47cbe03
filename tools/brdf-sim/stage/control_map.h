// The control unit of the simulated stage bus: a Modbus unit id (100 by default) whose holding
// registers set what is mounted in front of the meter and which faults the simulator injects,
// so tests and an operator can act on a running brdf-sim over the same Modbus link (TCP or RTU)
// the stage uses. Writes go into brdf::sim::SimControl; reads return its current values, so a
// "next N" counter reads back how many are left.
//
// Holding registers (PDU addresses, 0-based; a manual-style "4xxxx" number is address + 40001):
//
//   addr  name                      values
//   ----  ------------------------  ------------------------------------------------------------
//      0  mounted target            0 sample, 1 white reference, 2 dark (shutter closed)
//      1  power-cycle meter         write 1: the PR-650 endpoint power-cycles the meter; reads 0
//     10  serial.silent             0/1: the meter answers nothing
//     11  serial.garbage_next       N: the next N meter replies are garbage bytes
//     12  serial.truncate_next      N: the next N meter replies stop half-way
//     13  serial.quality_code       force this quality code (signed 16-bit: the PR-670's −8 is
//                                   0xFFF8) ...
//     14  serial.quality_count      ... for the next N measurements
//  15-16  serial.vanish_ms          32-bit, high word first: >0 = the port vanishes during the next
//                                   D5 transfer and comes back after this many (simulated) ms
//     17  serial.no_data_next       N: the next N measurements give no data (reports answer "-1")
//     18  serial.units_code         0 radiance, 1 irradiance, 2 uncalibrated: the reports' units
//     19  serial.leave_remote       1: the meter leaves remote mode at the next command (PR-670,
//                                   CS-2000: a driver that enters it again is answered again)
//     20  modbus.exception_code     exception (2 illegal address, 6 busy, ...) to reply with ...
//     21  modbus.exception_count    ... to the next N axis requests (the request is not applied)
//     22  modbus.late_reply_ms      delay the next N axis replies by this many real ms ...
//     23  modbus.late_count         ... (the request is applied on arrival; only the reply is late)
//     24  modbus.drop_connection    1: close the TCP connection at the next axis request (over RTU:
//                                   leave that request unanswered)
//     25  modbus.alarm_mid_move     1: the next move raises an alarm (code 0x30) half-way
//     26  modbus.stall              1: the next move never clears MOVE (until STOP or ALM-RST)
//     27  modbus.swap_word_order    0/1: the drives lay 32-bit values in the other word order than
//                                   configured (a setting that stays, as the drive's parameter)
//     28  modbus.outage_ms          N: at the next axis request the drives go away for N real ms:
//                                   that TCP connection closes, the listener closes (connections
//                                   are refused), axis requests meanwhile are dropped (RTU: left
//                                   unanswered); then the same port listens again. Reads N until
//                                   the outage starts, then 0
//     29  placed.by_hand            1: the operator has placed lamp and detector by hand (the
//                                   sample-fixed method): the optics use the directions below,
//                                   not the holder's pose; 0: the holder's pose again
//  30-33  placed.theta_i, phi_i,    the directions placed by hand, signed centidegrees (θ 0–9000,
//         theta_o, phi_o            φ −18000–18000); written before or with register 29
//
// Registers 2–9 read 0 and refuse writes (exception 02), as do addresses past 33.
// A value out of range (mounted 3, a flag of 2, exception code 12) is refused with exception 03
// and nothing of that write is applied. Faults apply to the axis unit ids only, never to the
// control unit itself, so setting a fault cannot consume it.
//
// Example (modbus-cli style): write 6 to 100:20 and 2 to 100:21 → the next two axis requests
// answer "device busy".
#pragma once

#include <algorithm>
#include <cmath>
#include <cstdint>

namespace brdf::sim::control_map {

inline constexpr int kDefaultUnitId = 100;

inline constexpr std::uint16_t kMountedTarget = 0;
inline constexpr std::uint16_t kPowerCycleMeter = 1;
inline constexpr std::uint16_t kSerialSilent = 10;
inline constexpr std::uint16_t kSerialGarbageNext = 11;
inline constexpr std::uint16_t kSerialTruncateNext = 12;
inline constexpr std::uint16_t kSerialQualityCode = 13;
inline constexpr std::uint16_t kSerialQualityCount = 14;
inline constexpr std::uint16_t kSerialVanishMs = 15;  // 2 registers, high word first
inline constexpr std::uint16_t kSerialNoDataNext = 17;
inline constexpr std::uint16_t kSerialUnitsCode = 18;
inline constexpr std::uint16_t kSerialLeaveRemote = 19;
inline constexpr std::uint16_t kModbusExceptionCode = 20;
inline constexpr std::uint16_t kModbusExceptionCount = 21;
inline constexpr std::uint16_t kModbusLateReplyMs = 22;
inline constexpr std::uint16_t kModbusLateCount = 23;
inline constexpr std::uint16_t kModbusDropConnection = 24;
inline constexpr std::uint16_t kModbusAlarmMidMove = 25;
inline constexpr std::uint16_t kModbusStall = 26;
inline constexpr std::uint16_t kModbusSwapWordOrder = 27;
inline constexpr std::uint16_t kModbusOutageMs = 28;

inline constexpr std::uint16_t kPlacedByHand = 29;
inline constexpr std::uint16_t kPlacedThetaI = 30;  // then phi_i, theta_o, phi_o
inline constexpr std::uint16_t kPlacedPhiO = 33;
// A placed angle in its register: signed centidegrees (two's complement), and back. The writer
// (brdfctl sim-mount) and the simulator's control unit read the same encoding from here.
inline std::uint16_t ToCentidegrees(double deg) {
  return static_cast<std::uint16_t>(
      static_cast<std::int16_t>(std::clamp<long>(std::lround(deg * 100), -32768, 32767)));
}
inline double FromCentidegrees(std::uint16_t reg) {
  return static_cast<std::int16_t>(reg) / 100.0;
}
// Whether `deg` fits placed register `address` (30–33): θ in 0–90°, φ in −180–180°.
inline bool PlacedAngleInRange(std::uint16_t address, double deg) {
  const bool theta = (address - kPlacedThetaI) % 2 == 0;
  return theta ? deg >= 0 && deg <= 90 : deg >= -180 && deg <= 180;
}

inline constexpr std::uint16_t kRegisterCount = 34;  // addresses 0–33

}  // namespace brdf::sim::control_map
