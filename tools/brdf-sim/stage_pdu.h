// The Modbus application layer of the simulated stage: one request PDU in, one response PDU out,
// against the registers of one unit id. Shared by the TCP and RTU endpoints, which only frame.
// Supports what stage drives are driven with: FC03/FC04 (read), FC06 (write one), FC16 (write
// many); anything else is exception 01.
#pragma once

#include <cstdint>
#include <span>
#include <vector>

namespace brdf::sim {

namespace modbus {
inline constexpr std::uint8_t kReadHoldingRegisters = 0x03;
inline constexpr std::uint8_t kReadInputRegisters = 0x04;
inline constexpr std::uint8_t kWriteSingleRegister = 0x06;
inline constexpr std::uint8_t kWriteMultipleRegisters = 0x10;

inline constexpr std::uint8_t kIllegalFunction = 0x01;
inline constexpr std::uint8_t kIllegalDataAddress = 0x02;
inline constexpr std::uint8_t kIllegalDataValue = 0x03;
inline constexpr std::uint8_t kDeviceBusy = 0x06;
inline constexpr std::uint8_t kGatewayTargetFailed = 0x0B;
}  // namespace modbus

// The holding registers of one unit id (an axis drive, the control unit). Returns 0 or the Modbus
// exception code to answer with; a failed call changes nothing.
class RegisterUnit {
 public:
  virtual ~RegisterUnit() = default;
  virtual std::uint8_t ReadRegisters(std::uint16_t address, std::uint16_t count,
                                     std::vector<std::uint16_t>& out) = 0;
  virtual std::uint8_t WriteRegisters(std::uint16_t address,
                                      std::span<const std::uint16_t> values) = 0;
};

// Function code with the exception bit, then the exception code.
std::vector<std::uint8_t> ExceptionPdu(std::uint8_t function, std::uint8_t code);

// Serves one request PDU (function code first) against `unit`.
std::vector<std::uint8_t> ServePdu(std::span<const std::uint8_t> request, RegisterUnit& unit);

}  // namespace brdf::sim
