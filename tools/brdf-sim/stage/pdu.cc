#include "tools/brdf-sim/stage/pdu.h"

#include <algorithm>
#include <cstdio>

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

std::optional<FunctionCodes> DocumentedFunctionCodes(std::string_view profile) {
  // Oriental Motor's AZ Modbus manuals: read holding registers, write single, diagnosis (sub
  // 00h only), write multiple. Leadshine's RS-485 drive manuals: 03, 06, 10h. Applied Motion's
  // Modbus register table: 03, 04, 06, 10h.
  if (profile == "az") return FunctionCodes{0x03, 0x06, 0x08, 0x10};
  if (profile == "leadshine") return FunctionCodes{0x03, 0x06, 0x10};
  if (profile == "moons") return FunctionCodes{0x03, 0x04, 0x06, 0x10};
  return std::nullopt;
}

std::optional<FunctionCodes> ParseFunctionCodes(std::string_view text, std::string* error) {
  if (auto named = DocumentedFunctionCodes(text)) return named;
  FunctionCodes codes;
  std::size_t start = 0;
  while (start <= text.size()) {
    const std::size_t comma = std::min(text.find(',', start), text.size());
    std::string_view item = text.substr(start, comma - start);
    while (!item.empty() && item.front() == ' ') item.remove_prefix(1);
    while (!item.empty() && item.back() == ' ') item.remove_suffix(1);
    int value = 0;
    bool digits = !item.empty() && item.size() <= 3;
    for (char c : item) {
      digits = digits && c >= '0' && c <= '9';
      value = value * 10 + (c - '0');
    }
    const bool served =
        digits && std::find(kServedFunctionCodes.begin(), kServedFunctionCodes.end(), value) !=
                      kServedFunctionCodes.end();
    if (!served) {
      *error = "function code '" + std::string(item) + "' is not one brdf-sim serves (" +
               DescribeFunctionCodes(kServedFunctionCodes) +
               "); give a profile (az, leadshine, moons) or a list such as \"3,6,8,16\"";
      return std::nullopt;
    }
    if (std::find(codes.begin(), codes.end(), value) == codes.end()) {
      codes.push_back(static_cast<std::uint8_t>(value));
    }
    start = comma + 1;
  }
  std::sort(codes.begin(), codes.end());
  return codes;
}

std::string DescribeFunctionCodes(const FunctionCodes& codes) {
  std::string out;
  for (std::uint8_t c : codes) {
    char text[8];
    std::snprintf(text, sizeof text, "%02d", c);
    out += (out.empty() ? "" : ", ") + std::string(text);
  }
  return out;
}

std::vector<std::uint8_t> ExceptionPdu(std::uint8_t function, std::uint8_t code) {
  return {static_cast<std::uint8_t>(function | 0x80), code};
}

std::vector<std::uint8_t> ServePdu(std::span<const std::uint8_t> req, RegisterUnit& unit,
                                   const FunctionCodes& accepted) {
  if (req.empty()) return ExceptionPdu(0, modbus::kIllegalFunction);
  const std::uint8_t fc = req[0];
  if (std::find(accepted.begin(), accepted.end(), fc) == accepted.end()) {
    return ExceptionPdu(fc, modbus::kIllegalFunction);
  }
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
    case modbus::kDiagnostics: {
      // Sub-function (2 bytes), then data in whole registers: Return Query Data echoes it all.
      if (req.size() < 5 || (req.size() - 3) % 2 != 0) {
        return ExceptionPdu(fc, modbus::kIllegalDataValue);
      }
      if (Be16(req, 1) != modbus::kReturnQueryData) {
        return ExceptionPdu(fc, modbus::kIllegalFunction);
      }
      return std::vector<std::uint8_t>(req.begin(), req.end());
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
