// The Modbus application layer of the simulated stage: one request PDU in, one response PDU out,
// against the registers of one unit id. Shared by the TCP and RTU endpoints, which only frame.
// Implements FC03/FC04 (read), FC06 (write one), FC08 (diagnostics, sub-function 0x0000 Return
// Query Data) and FC16 (write many); a unit answers only the function codes its drive documents
// (FunctionCodes) and any other with exception 01, as a real drive does.
#pragma once

#include <cstdint>
#include <optional>
#include <span>
#include <string>
#include <string_view>
#include <vector>

namespace brdf::sim {

namespace modbus {
inline constexpr std::uint8_t kReadHoldingRegisters = 0x03;
inline constexpr std::uint8_t kReadInputRegisters = 0x04;
inline constexpr std::uint8_t kWriteSingleRegister = 0x06;
inline constexpr std::uint8_t kDiagnostics = 0x08;
inline constexpr std::uint16_t kReturnQueryData = 0x0000;  // FC08 sub-function: echo
inline constexpr std::uint8_t kWriteMultipleRegisters = 0x10;

inline constexpr std::uint8_t kIllegalFunction = 0x01;
inline constexpr std::uint8_t kIllegalDataAddress = 0x02;
inline constexpr std::uint8_t kIllegalDataValue = 0x03;
inline constexpr std::uint8_t kDeviceFailure = 0x04;  // AZ: busy, command execution disabled
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

// The function codes a unit answers, in increasing order.
using FunctionCodes = std::vector<std::uint8_t>;

// Everything ServePdu implements (the control unit answers all of them).
inline const FunctionCodes kServedFunctionCodes = {0x03, 0x04, 0x06, 0x08, 0x10};

// The function codes a drive's Modbus manual documents, by brdfd's profile name
// (docs/stage-modbus.md): `az` (Oriental Motor AZ) 03, 06, 08, 16; `leadshine` 03, 06, 16;
// `moons` (Applied Motion) 03, 04, 06, 16. std::nullopt for another name.
std::optional<FunctionCodes> DocumentedFunctionCodes(std::string_view profile);

// A profile name, or a comma-separated list of decimal function codes ("3,6,8,16"), each one
// ServePdu implements. std::nullopt with `error` set otherwise.
std::optional<FunctionCodes> ParseFunctionCodes(std::string_view text, std::string* error);

// "03, 06, 08, 16": for messages and logs.
std::string DescribeFunctionCodes(const FunctionCodes& codes);

// Function code with the exception bit, then the exception code.
std::vector<std::uint8_t> ExceptionPdu(std::uint8_t function, std::uint8_t code);

// Serves one request PDU (function code first) against `unit`. A function code outside `accepted`
// is exception 01 before anything is read; a PDU too short or too long for its function, a count
// out of range or a byte count that disagrees with the count is exception 03; an FC08
// sub-function other than Return Query Data is exception 01 (the AZ documents only 0x0000).
std::vector<std::uint8_t> ServePdu(std::span<const std::uint8_t> request, RegisterUnit& unit,
                                   const FunctionCodes& accepted = kServedFunctionCodes);

}  // namespace brdf::sim
