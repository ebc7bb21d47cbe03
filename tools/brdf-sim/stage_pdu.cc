#include "tools/brdf-sim/stage_pdu.h"

namespace brdf::sim {

namespace {

std::uint16_t Be16(std::span<const std::uint8_t> b, std::size_t at) {
  return static_cast<std::uint16_t>((b[at] << 8) | b[at + 1]);
}

void PutBe16(std::vector<std::uint8_t>& out, std::uint16_t v) {
  out.push_back(static_cast<std::uint8_t>(v >> 8));
  out.push_back(static_cast<std::uint8_t>(v & 0xFF));
}

}  // namespace

std::vector<std::uint8_t> ExceptionPdu(std::uint8_t function, std::uint8_t code) {
  return {static_cast<std::uint8_t>(function | 0x80), code};
}

std::vector<std::uint8_t> ServePdu(std::span<const std::uint8_t> req, RegisterUnit& unit) {
  if (req.empty()) return ExceptionPdu(0, modbus::kIllegalFunction);
  const std::uint8_t fc = req[0];
  switch (fc) {
    case modbus::kReadHoldingRegisters:
    case modbus::kReadInputRegisters: {
      if (req.size() != 5) return ExceptionPdu(fc, modbus::kIllegalDataValue);
      const std::uint16_t address = Be16(req, 1);
      const std::uint16_t count = Be16(req, 3);
      if (count < 1 || count > 125) return ExceptionPdu(fc, modbus::kIllegalDataValue);
      if (address + count > 0x10000) return ExceptionPdu(fc, modbus::kIllegalDataAddress);
      std::vector<std::uint16_t> regs;
      if (const std::uint8_t ex = unit.ReadRegisters(address, count, regs); ex != 0) {
        return ExceptionPdu(fc, ex);
      }
      std::vector<std::uint8_t> out{fc, static_cast<std::uint8_t>(2 * count)};
      for (std::uint16_t r : regs) PutBe16(out, r);
      return out;
    }
    case modbus::kWriteSingleRegister: {
      if (req.size() != 5) return ExceptionPdu(fc, modbus::kIllegalDataValue);
      const std::uint16_t value = Be16(req, 3);
      if (const std::uint8_t ex = unit.WriteRegisters(Be16(req, 1), std::span(&value, 1));
          ex != 0) {
        return ExceptionPdu(fc, ex);
      }
      return std::vector<std::uint8_t>(req.begin(), req.end());  // echo
    }
    case modbus::kWriteMultipleRegisters: {
      if (req.size() < 6) return ExceptionPdu(fc, modbus::kIllegalDataValue);
      const std::uint16_t address = Be16(req, 1);
      const std::uint16_t count = Be16(req, 3);
      const std::size_t bytes = req[5];
      if (count < 1 || count > 123 || bytes != 2u * count || req.size() != 6 + bytes) {
        return ExceptionPdu(fc, modbus::kIllegalDataValue);
      }
      if (address + count > 0x10000) return ExceptionPdu(fc, modbus::kIllegalDataAddress);
      std::vector<std::uint16_t> values(count);
      for (std::size_t i = 0; i < count; ++i) values[i] = Be16(req, 6 + 2 * i);
      if (const std::uint8_t ex = unit.WriteRegisters(address, values); ex != 0) {
        return ExceptionPdu(fc, ex);
      }
      std::vector<std::uint8_t> out{fc};
      PutBe16(out, address);
      PutBe16(out, count);
      return out;
    }
    default:
      return ExceptionPdu(fc, modbus::kIllegalFunction);
  }
}

}  // namespace brdf::sim
