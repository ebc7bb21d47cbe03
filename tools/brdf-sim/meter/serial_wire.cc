#include "tools/brdf-sim/meter/serial_wire.h"

#include <poll.h>
#include <unistd.h>

#include <algorithm>
#include <cctype>
#include <cerrno>
#include <thread>

namespace brdf::sim {

namespace {

using SteadyClock = std::chrono::steady_clock;
constexpr auto kSlice = std::chrono::milliseconds(20);
// A reply nobody reads (the pty's buffer is full) is given up after this long.
constexpr auto kWriteStall = std::chrono::seconds(2);

}  // namespace

std::string UpperAscii(std::string s) {
  for (char& c : s) c = static_cast<char>(std::toupper(static_cast<unsigned char>(c)));
  return s;
}

std::string TrimBlanks(const std::string& s) {
  const auto first = s.find_first_not_of(" \t");
  if (first == std::string::npos) return {};
  const auto last = s.find_last_not_of(" \t");
  return s.substr(first, last - first + 1);
}

std::string GarbleLine(const std::string& line, unsigned seed) {
  static const char kJunk[] = "\x7f#~?@%&\xff\xfe\x1b!*";
  std::string out(line.size(), '#');
  for (std::size_t i = 0; i < out.size(); ++i) out[i] = kJunk[(seed + i * 7) % (sizeof kJunk - 1)];
  return out;
}

bool SleepUnlessStopped(std::chrono::nanoseconds d, const std::atomic<bool>& stop) {
  const auto end = SteadyClock::now() + d;
  while (!stop) {
    const auto now = SteadyClock::now();
    if (now >= end) return true;
    std::this_thread::sleep_for(std::min<SteadyClock::duration>(end - now, kSlice));
  }
  return false;
}

bool WriteWire(int fd, const std::string& bytes, const WirePace& q, const std::atomic<bool>& stop) {
  if (fd < 0) return false;
  // Serial pacing: one byte is 10 bits (start, 8 data, stop) on the wire.
  const double byte_sim_s = 10.0 / std::max(q.baud, 1);
  const std::size_t piece =
      q.piece_bytes > 0 ? static_cast<std::size_t>(q.piece_bytes) : bytes.size();
  const auto start = SteadyClock::now();
  auto paused = SteadyClock::duration::zero();  // piece gaps do not count as transmission time
  std::size_t sent = 0;
  auto last_progress = start;
  while (sent < bytes.size()) {
    if (stop) return false;
    // Never write across the end of the current piece.
    std::size_t chunk = std::min(bytes.size(), (sent / piece + 1) * piece) - sent;
    if (q.pace) {
      // Byte k (counting from 0) is due k byte-times after the start. The next burst leaves
      // once its last byte is due; then everything due goes (more than a burst if late).
      const auto elapsed =
          std::chrono::duration_cast<std::chrono::nanoseconds>(SteadyClock::now() - start - paused);
      const double elapsed_sim = q.time_scale.ToSim(elapsed);
      const auto due = static_cast<std::size_t>(elapsed_sim / byte_sim_s) + 1;
      const std::size_t burst_end =
          sent + std::min(chunk, static_cast<std::size_t>(std::max(q.fifo_bytes, 1)));
      if (due < burst_end) {
        const double wait_sim = static_cast<double>(burst_end - 1) * byte_sim_s - elapsed_sim;
        SleepUnlessStopped(
            std::clamp<std::chrono::nanoseconds>(q.time_scale.ToReal(wait_sim),
                                                 std::chrono::microseconds(50), kSlice),
            stop);
        continue;
      }
      chunk = std::min(chunk, due - sent);
    }
    const ssize_t n = ::write(fd, bytes.data() + sent, chunk);
    if (n > 0) {
      sent += static_cast<std::size_t>(n);
      last_progress = SteadyClock::now();
      if (sent % piece == 0 && sent < bytes.size() && q.piece_gap.count() > 0) {
        const auto before = SteadyClock::now();
        if (!SleepUnlessStopped(q.piece_gap, stop)) return false;
        paused += SteadyClock::now() - before;
      }
      continue;
    }
    if (n < 0 && errno != EAGAIN && errno != EINTR) return false;
    if (SteadyClock::now() - last_progress > kWriteStall) return false;  // nobody is reading
    pollfd p{fd, POLLOUT, 0};
    ::poll(&p, 1, static_cast<int>(kSlice.count()));
  }
  return true;
}

}  // namespace brdf::sim
