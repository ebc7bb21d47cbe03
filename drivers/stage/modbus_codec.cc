#include "drivers/stage/modbus_codec.h"

#include <cmath>
#include <limits>
#include <string>

namespace brdf::drivers::stage {

namespace {

constexpr double kInt32Min = static_cast<double>(std::numeric_limits<std::int32_t>::min());
constexpr double kInt32Max = static_cast<double>(std::numeric_limits<std::int32_t>::max());

// Rounds half away from zero and checks the int32 range; `what` names the value in messages.
Result<std::int32_t> RoundToInt32(double value, const char* what) {
  if (!std::isfinite(value)) {
    return InvalidArgument(std::string(what) + " is not a finite number");
  }
  const double rounded = std::round(value);
  if (rounded < kInt32Min || rounded > kInt32Max) {
    return InvalidArgument(std::string(what) + " " + std::to_string(rounded) +
                           " does not fit a signed 32-bit register pair");
  }
  return static_cast<std::int32_t>(rounded);
}

}  // namespace

std::array<std::uint16_t, 2> PackInt32(std::int32_t value, WordOrder order) {
  const auto bits = static_cast<std::uint32_t>(value);
  const auto high = static_cast<std::uint16_t>(bits >> 16);
  const auto low = static_cast<std::uint16_t>(bits & 0xFFFFu);
  if (order == WordOrder::kHighFirst) return {high, low};
  return {low, high};
}

std::int32_t UnpackInt32(std::uint16_t first, std::uint16_t second, WordOrder order) {
  const std::uint16_t high = order == WordOrder::kHighFirst ? first : second;
  const std::uint16_t low = order == WordOrder::kHighFirst ? second : first;
  const std::uint32_t bits =
      (static_cast<std::uint32_t>(high) << 16) | static_cast<std::uint32_t>(low);
  return static_cast<std::int32_t>(bits);  // two's complement (guaranteed since C++20)
}

void EncodeField(std::int32_t value, int words, WordOrder order, std::span<std::uint16_t> out) {
  if (words == 1) {
    out[0] = static_cast<std::uint16_t>(static_cast<std::uint32_t>(value) & 0xFFFFu);
    return;
  }
  const auto packed = PackInt32(value, order);
  out[0] = packed[0];
  out[1] = packed[1];
}

std::int32_t DecodeSigned(std::span<const std::uint16_t> regs, WordOrder order) {
  if (regs.size() == 1) return static_cast<std::int16_t>(regs[0]);
  return UnpackInt32(regs[0], regs[1], order);
}

std::uint32_t DecodeUnsigned(std::span<const std::uint16_t> regs, WordOrder order) {
  if (regs.size() == 1) return regs[0];
  return static_cast<std::uint32_t>(UnpackInt32(regs[0], regs[1], order));
}

bool FitsField(std::int64_t value, int words, bool is_signed) {
  if (words == 1) {
    if (is_signed) {
      return value >= std::numeric_limits<std::int16_t>::min() &&
             value <= std::numeric_limits<std::int16_t>::max();
    }
    return value >= 0 && value <= std::numeric_limits<std::uint16_t>::max();
  }
  if (words == 2) {
    if (is_signed) {
      return value >= std::numeric_limits<std::int32_t>::min() &&
             value <= std::numeric_limits<std::int32_t>::max();
    }
    return value >= 0 && value <= std::numeric_limits<std::uint32_t>::max();
  }
  return false;
}

Result<std::int32_t> DegreesToCounts(double degrees, double counts_per_degree,
                                     std::int32_t zero_offset_counts) {
  if (!std::isfinite(degrees)) return InvalidArgument("angle is not a finite number");
  return RoundToInt32(degrees * counts_per_degree + static_cast<double>(zero_offset_counts),
                      "position in counts");
}

double CountsToDegrees(std::int32_t counts, double counts_per_degree,
                       std::int32_t zero_offset_counts) {
  return (static_cast<double>(counts) - static_cast<double>(zero_offset_counts)) /
         counts_per_degree;
}

Result<std::int32_t> SpeedToRegister(double deg_per_s, double counts_per_degree, double scale) {
  return RoundToInt32(deg_per_s * counts_per_degree * scale, "speed register value");
}

StatusFlags DecodeStatus(std::uint32_t status_word, const StatusBits& bits) {
  StatusFlags f;
  f.ready = (status_word & bits.ready) != 0;
  f.alarm = (status_word & bits.alarm) != 0;
  f.busy = (status_word & bits.busy) != 0;
  f.moving = (status_word & bits.moving) != 0;
  f.in_position =
      bits.in_position != 0 ? (status_word & bits.in_position) != 0 : (!f.moving && !f.alarm);
  return f;
}

}  // namespace brdf::drivers::stage
