#include "tools/brdf-sim/stage/rtu_frame.h"

namespace brdf::sim {

std::uint16_t ModbusCrc16(std::span<const std::uint8_t> bytes) {
  std::uint16_t crc = 0xFFFF;
  for (std::uint8_t b : bytes) {
    crc ^= b;
    for (int i = 0; i < 8; ++i) {
      crc = (crc & 1) != 0 ? static_cast<std::uint16_t>((crc >> 1) ^ 0xA001)
                           : static_cast<std::uint16_t>(crc >> 1);
    }
  }
  return crc;
}

void AppendCrc(std::vector<std::uint8_t>& frame) {
  const std::uint16_t crc = ModbusCrc16(frame);
  frame.push_back(static_cast<std::uint8_t>(crc & 0xFF));
  frame.push_back(static_cast<std::uint8_t>(crc >> 8));
}

int RtuRequestLength(std::span<const std::uint8_t> bytes) {
  if (bytes.size() < 2) return 0;
  switch (bytes[1]) {
    case 0x01:
    case 0x02:
    case 0x03:
    case 0x04:
    case 0x05:
    case 0x06:
      return 8;  // slave, fc, address(2), count/value(2), crc(2)
    case 0x08:
      return 8;  // slave, fc, sub-function(2), one data word (the AZ's diagnosis form), crc(2)
    case 0x0F:
    case 0x10:
      if (bytes.size() < 7) return 0;
      return 9 + bytes[6];  // slave, fc, address(2), count(2), byte count, data, crc(2)
    default:
      return -1;
  }
}

void RtuFrameSplitter::Feed(std::span<const std::uint8_t> bytes, TimePoint now) {
  if (bytes.empty()) return;
  Expire(now);
  buffer_.insert(buffer_.end(), bytes.begin(), bytes.end());
  last_byte_ = now;
}

void RtuFrameSplitter::Expire(TimePoint now) {
  if (!buffer_.empty() && now - last_byte_ > gap_) {
    dropped_bytes_ += static_cast<int>(buffer_.size());
    buffer_.clear();
  }
}

std::optional<std::vector<std::uint8_t>> RtuFrameSplitter::Next() {
  while (buffer_.size() >= 2) {
    const int length = RtuRequestLength(buffer_);
    if (length == 0) return std::nullopt;
    if (length > 0 && buffer_.size() < static_cast<std::size_t>(length)) return std::nullopt;
    if (length > 0) {
      const auto n = static_cast<std::size_t>(length);
      const std::uint16_t crc = ModbusCrc16(std::span(buffer_).first(n - 2));
      if ((crc & 0xFF) == buffer_[n - 2] && (crc >> 8) == buffer_[n - 1]) {
        std::vector<std::uint8_t> frame(buffer_.begin(),
                                        buffer_.begin() + static_cast<long>(n - 2));
        buffer_.erase(buffer_.begin(), buffer_.begin() + static_cast<long>(n));
        return frame;
      }
      ++crc_errors_;
    }
    // Not a frame start: skip one byte and try again.
    buffer_.erase(buffer_.begin());
    ++dropped_bytes_;
  }
  return std::nullopt;
}

}  // namespace brdf::sim
