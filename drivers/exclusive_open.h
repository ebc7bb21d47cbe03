// One owner per device file: a process that opens a serial port takes an advisory flock(2) on it
// (another brdfd, `flock`, minicom and most serial tools take the same lock) and sets TIOCEXCL
// (further open(2)s of the terminal fail with EBUSY, except for root). Refusals name the process
// that holds the file, found in /proc/locks, so the operator knows what to stop.
#pragma once

#include <optional>
#include <string>

#include "core/status.h"

namespace brdf::drivers {

// "pid 1234 (brdfd --config /etc/brdfd/brdfd.toml)", from /proc/<pid>/cmdline (cut to 160
// characters); "pid 1234" when the command line cannot be read.
std::string DescribeProcess(int pid);

// The pid of a process holding a lock (flock or fcntl) on the file at `path`, from /proc/locks;
// nullopt when none is listed or the file cannot be examined.
std::optional<int> LockHolder(const std::string& path);

// Takes an exclusive, non-blocking flock on `fd` (the device at `path`) and sets TIOCEXCL when it
// is a terminal. kFailedPrecondition naming the holder when another process holds the lock
// ("serial port P is in use by pid N (...): stop that program or set [meter] port ..."). The lock
// lives as long as the file descriptor.
Status LockDeviceExclusively(int fd, const std::string& path);

// Looks, without keeping anything open, whether another process holds the device at `path`
// (its flock, or an exclusive open that refuses ours). Ok when the device is free or absent
// (an absent device is the connection supervisor's business); kFailedPrecondition naming the
// holder otherwise.
Status CheckDeviceFree(const std::string& path);

}  // namespace brdf::drivers
