#include "drivers/serial/fd_io.h"

#include <poll.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <cstring>

namespace brdf::drivers::serial {

namespace {

// Milliseconds to poll for: the time left until `end`, rounded up, at most one slice.
int PollMillis(std::chrono::steady_clock::time_point now,
               std::chrono::steady_clock::time_point end) {
  if (now >= end) return 0;
  const auto left = std::chrono::ceil<std::chrono::milliseconds>(end - now);
  return static_cast<int>(std::min(left, kWaitSlice).count());
}

Status CancelledOn(const std::string& port, const CallContext& ctx) {
  return Cancelled("I/O on serial port " + port + " cancelled (" + ctx.cancel().reason() + ")");
}

bool IsHangup(short revents) {
  return (revents & (POLLHUP | POLLERR | POLLNVAL)) != 0;
}

}  // namespace

Status VanishedError(const std::string& port, std::string_view during, int err) {
  const std::string cause = err == 0 ? "hang-up" : std::strerror(err);
  return Disconnected("serial port " + port + " vanished during " + std::string(during) + " (" +
                      cause +
                      "); check the USB-serial adapter and cable, then connect again once the "
                      "port is back");
}

Result<std::string> ReadAvailable(int fd, const std::string& port,
                                  std::chrono::steady_clock::time_point until,
                                  const CallContext& ctx) {
  const auto end = std::min(until, ctx.deadline());
  while (true) {
    if (ctx.cancelled()) return CancelledOn(port, ctx);
    const auto now = ctx.clock().Now();
    pollfd p{fd, POLLIN, 0};
    const int ready = ::poll(&p, 1, PollMillis(now, end));
    if (ready < 0) {
      if (errno == EINTR) continue;
      return VanishedError(port, "poll", errno);
    }
    if (ready > 0) {
      if (p.revents & POLLIN) {
        char buffer[4096];
        const ssize_t n = ::read(fd, buffer, sizeof buffer);
        if (n > 0) return std::string(buffer, static_cast<std::size_t>(n));
        if (n < 0 && errno != EAGAIN && errno != EINTR) return VanishedError(port, "read", errno);
        // A tty in raw mode with VMIN = VTIME = 0 reads 0 bytes both when nothing is there and
        // after a hang-up; only the poll flags tell which.
        if (IsHangup(p.revents)) return VanishedError(port, "read", 0);
      } else if (IsHangup(p.revents)) {
        return VanishedError(port, "read", 0);
      }
    }
    if (ctx.clock().Now() >= end) return std::string();
  }
}

Status WriteAll(int fd, const std::string& port, std::string_view bytes, const CallContext& ctx) {
  std::size_t written = 0;
  while (written < bytes.size()) {
    if (ctx.cancelled()) return CancelledOn(port, ctx);
    const ssize_t n = ::write(fd, bytes.data() + written, bytes.size() - written);
    if (n > 0) {
      written += static_cast<std::size_t>(n);
      continue;
    }
    if (n < 0 && errno != EAGAIN && errno != EINTR) return VanishedError(port, "write", errno);
    const auto now = ctx.clock().Now();
    if (now >= ctx.deadline()) {
      return Timeout("could not write to serial port " + port + " before the deadline (" +
                     std::to_string(written) + " of " + std::to_string(bytes.size()) +
                     " bytes sent); with hardware flow control on, check the cable's RTS/CTS "
                     "lines or switch flow control off");
    }
    pollfd p{fd, POLLOUT, 0};
    const int ready = ::poll(&p, 1, PollMillis(now, ctx.deadline()));
    if (ready < 0 && errno != EINTR) return VanishedError(port, "poll", errno);
    if (ready > 0 && IsHangup(p.revents)) return VanishedError(port, "write", 0);
  }
  return Status::Ok();
}

Status OpenError(int err, const std::string& port, bool seen_before) {
  const std::string cause = std::strerror(err);
  switch (err) {
    case ENOENT:
    case ENODEV:
    case ENXIO:
      if (seen_before) return VanishedError(port, "open", err);
      return ConfigurationError("cannot open serial port " + port + " (" + cause +
                                "): check the port name in the configuration (ls /dev/ttyUSB* "
                                "/dev/serial/by-id) and that the USB-serial adapter is plugged in");
    case EACCES:
    case EPERM:
      return ConfigurationError("cannot open serial port " + port + " (" + cause +
                                "): give the daemon's user access, e.g. add it to the dialout "
                                "group");
    case EBUSY:
      return FailedPrecondition("serial port " + port + " is in use by another program (" + cause +
                                "): close that program (fuser " + port + ") and connect again");
    case EIO:
      return VanishedError(port, "open", err);
    default:
      return ConfigurationError("cannot open serial port " + port + " (" + cause +
                                "): check the port name in the configuration");
  }
}

}  // namespace brdf::drivers::serial
