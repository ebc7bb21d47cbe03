// Pure encoding and decoding between the drive's registers and the lab's units: 32-bit values in
// two 16-bit registers (either word order), degrees ↔ counts, the status word. No I/O and no state,
// so every function here can be unit-tested and fuzzed on its own.
//
// libmodbus 3.1.6's MODBUS_GET_INT32_FROM_INT16 shifts a uint16_t without a cast (int promotion
// overflows for the high word ≥ 0x8000), so 32-bit values are packed and unpacked here with
// explicit casts instead.
#pragma once

#include <array>
#include <cstdint>
#include <span>

#include "core/status.h"
#include "drivers/stage/register_profile.h"

namespace brdf::drivers::stage {

// The two registers of `value`, in address order.
std::array<std::uint16_t, 2> PackInt32(std::int32_t value, WordOrder order);
// `first` is the register at the lower address.
std::int32_t UnpackInt32(std::uint16_t first, std::uint16_t second, WordOrder order);

// Writes `value` into `words` (1 or 2) registers. A 1-word field takes the low 16 bits; callers
// check the range first with FitsField.
void EncodeField(std::int32_t value, int words, WordOrder order, std::span<std::uint16_t> out);
// Signed value of a 1- or 2-word field (a 1-word field is sign-extended).
std::int32_t DecodeSigned(std::span<const std::uint16_t> regs, WordOrder order);
// Unsigned value of a 1- or 2-word field (status words, bit masks).
std::uint32_t DecodeUnsigned(std::span<const std::uint16_t> regs, WordOrder order);
// Whether `value` can be stored in a field of `words` registers and read back unchanged: signed
// fields (positions) read back sign-extended, unsigned ones (speeds, masks, opcodes) do not.
bool FitsField(std::int64_t value, int words, bool is_signed);

// Degrees to the drive's counts: round(deg × counts_per_degree) + zero_offset, rounding half away
// from zero. kInvalidArgument for a non-finite angle or a result outside int32.
Result<std::int32_t> DegreesToCounts(double degrees, double counts_per_degree,
                                     std::int32_t zero_offset_counts);
double CountsToDegrees(std::int32_t counts, double counts_per_degree,
                       std::int32_t zero_offset_counts);

// Speed register value for `deg_per_s`: round(deg/s × counts/° × scale). Same errors as above.
Result<std::int32_t> SpeedToRegister(double deg_per_s, double counts_per_degree, double scale);

struct StatusFlags {
  bool ready = false;
  bool alarm = false;
  bool busy = false;
  bool moving = false;
  bool in_position = false;
};
// Applies the masks; a zero in_position mask derives IN-POS from "not moving and no alarm".
StatusFlags DecodeStatus(std::uint32_t status_word, const StatusBits& bits);
// A move is complete when MOVE is clear and IN-POS is set (and no alarm).
inline bool MoveComplete(const StatusFlags& f) {
  return !f.moving && f.in_position && !f.alarm;
}

}  // namespace brdf::drivers::stage
