// Modbus RTU framing for the simulator's RS-485 endpoint: CRC-16/MODBUS and a splitter that cuts
// the byte stream of a multi-drop line into request frames by length and timing, checking each
// CRC. (libmodbus 3.1.6's RTU server answers only one slave id and, after ignoring a frame for
// another id, swallows the next one, so the simulator frames RTU itself.)
#pragma once

#include <chrono>
#include <cstdint>
#include <optional>
#include <span>
#include <vector>

namespace brdf::sim {

// CRC-16/MODBUS (poly 0xA001 reflected, init 0xFFFF). On the wire: low byte first.
std::uint16_t ModbusCrc16(std::span<const std::uint8_t> bytes);

// Appends the CRC (low byte first) to `frame`.
void AppendCrc(std::vector<std::uint8_t>& frame);

// Length of the RTU request frame (slave id, PDU, CRC) that starts `bytes`: 0 if more bytes are
// needed to know, -1 if the function code is not one a request length can be derived for.
int RtuRequestLength(std::span<const std::uint8_t> bytes);

class RtuFrameSplitter {
 public:
  using TimePoint = std::chrono::steady_clock::time_point;
  // A silence longer than `gap` ends any unfinished frame (t3.5 is meaningless on a pty; a
  // generous gap keeps bursts together and still drops half frames).
  explicit RtuFrameSplitter(std::chrono::milliseconds gap = std::chrono::milliseconds(50))
      : gap_(gap) {}

  // Adds bytes received at `now`.
  void Feed(std::span<const std::uint8_t> bytes, TimePoint now);
  // The next complete frame with a valid CRC (slave id and PDU, CRC removed). Bytes that cannot
  // start a valid frame are skipped one at a time until the stream resynchronizes.
  std::optional<std::vector<std::uint8_t>> Next();
  // Drops an unfinished frame that has been silent longer than the gap.
  void Expire(TimePoint now);

  std::size_t buffered() const { return buffer_.size(); }
  int crc_errors() const { return crc_errors_; }
  int dropped_bytes() const { return dropped_bytes_; }

 private:
  std::chrono::milliseconds gap_;
  std::vector<std::uint8_t> buffer_;
  TimePoint last_byte_{};
  int crc_errors_ = 0;
  int dropped_bytes_ = 0;
};

}  // namespace brdf::sim
