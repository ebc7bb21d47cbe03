// The byte-transport seam under the PR-650 driver: open a serial port, write bytes, read bytes
// until a deadline, empty the input buffer, drive RTS. Nothing here knows the PR-650 protocol.
//
// Two implementations:
//  - libserialport, for real ports (/dev/ttyUSB*, /dev/ttyS*);
//  - plain termios, for pseudo-terminals (the simulator's pty, or a socat pair). libserialport
//    0.1.1 cannot open a pty at all: sp_get_port_by_name() looks the name up under
//    /sys/class/tty and sp_open() fails on the modem-line ioctl (TIOCMGET) that a pty lacks.
// MakeSerialLink() picks one from the port name; on a pty, RTS and line settings the pty does not
// support (ENOTTY/EINVAL) are logged and tolerated, never fatal.
//
// Errors: kConfigurationError (no such port before it ever opened, permissions, not a tty),
// kDisconnected (the port vanished: read/write error, hang-up, EIO), kCancelled,
// kFailedPrecondition (port busy, link not open).
#pragma once

#include <chrono>
#include <functional>
#include <memory>
#include <string>
#include <string_view>

#include "core/call_context.h"
#include "core/status.h"

namespace brdf::drivers::serial {

// Where the driver's diagnostics go (the daemon wires this to its logger).
using LogSink = std::function<void(std::string_view message)>;

struct SerialSettings {
  std::string port;                    // "/dev/ttyUSB0", or a pty path / link to one
  int baud = 9600;                     // 8 data bits, no parity, 1 stop bit
  bool hardware_flow_control = false;  // RTS/CTS; off by default, as the meter ships
  std::string device = "PR-650";       // the meter on the line, for messages ("PR-670")
};

class SerialLink {
 public:
  using TimePoint = std::chrono::steady_clock::time_point;

  virtual ~SerialLink() = default;

  // Opens and configures the port (raw, 8N1). `seen_before`: the port has been open before, so a
  // port that is now missing has vanished (kDisconnected) rather than been misnamed
  // (kConfigurationError).
  virtual Status Open(bool seen_before) = 0;
  virtual void Close() = 0;
  virtual bool is_open() const = 0;
  virtual const std::string& port() const = 0;

  // Writes all of `bytes`, waiting for room up to the context's deadline.
  virtual Status Write(std::string_view bytes, const CallContext& ctx) = 0;

  // Returns the bytes that are available, waiting for the first one until `until` or the
  // context's deadline, whichever is earlier (checking cancellation at least every 20 ms). An empty
  // string means nothing arrived in time: timeouts are the caller's to judge. `until` in the past
  // makes this a non-blocking poll.
  virtual Result<std::string> Read(TimePoint until, const CallContext& ctx) = 0;

  // Discards bytes received but not yet read (stale replies, line noise).
  virtual Status FlushInput() = 0;

  // Drives RTS. On a pty this is not supported: logged and reported OK.
  virtual Status SetRts(bool on) = 0;
};

// True if `port` is (or links to) a pseudo-terminal slave (/dev/pts/N).
bool IsPseudoTerminal(const std::string& port);

// A closed link for `settings.port`: termios for a pty, libserialport for anything else. Checks
// the settings (kConfigurationError: empty port name, unsupported baud rate).
Result<std::unique_ptr<SerialLink>> MakeSerialLink(const SerialSettings& settings, LogSink log);

// Baud rates both implementations accept.
bool IsSupportedBaud(int baud);

}  // namespace brdf::drivers::serial
