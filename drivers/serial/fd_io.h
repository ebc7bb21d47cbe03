// Byte I/O on an open serial file descriptor, shared by both SerialLink implementations: waiting
// in slices of at most 20 ms so cancellation is noticed promptly, and telling "no data yet" from
// "the port is gone" (hang-up, EIO), which is what a pulled USB adapter or a closed pty master
// looks like.
#pragma once

#include <string>
#include <string_view>

#include "core/call_context.h"
#include "core/status.h"

namespace brdf::drivers::serial {

// The longest single wait inside any PR-650 I/O loop.
inline constexpr std::chrono::milliseconds kWaitSlice{20};

// See SerialLink::Read.
Result<std::string> ReadAvailable(int fd, const std::string& port,
                                  std::chrono::steady_clock::time_point until,
                                  const CallContext& ctx);

// See SerialLink::Write.
Status WriteAll(int fd, const std::string& port, std::string_view bytes, const CallContext& ctx);

// The Status for open(2) (or an equivalent) failing on `port` with errno `err`.
Status OpenError(int err, const std::string& port, bool seen_before);

// "serial port /dev/ttyUSB0 vanished (read: Input/output error); ..." for an errno (0: hang-up).
Status VanishedError(const std::string& port, std::string_view during, int err);

}  // namespace brdf::drivers::serial
