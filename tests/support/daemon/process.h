// Runs the built brdfd as a child process (tests/support/process_launcher.h) for the daemon's
// integration tests: starts it with a
// configuration file, waits for its one stdout line "brdfd listening on <address>", and stops it
// with SIGTERM (a clean shutdown, exit code returned) or SIGKILL (a crash). Its stderr (the log)
// goes to a file, shown by log() when a test fails.
//
// The binary is $BRDF_BUILD_DIR/daemon/brdfd (brdf_add_test sets BRDF_BUILD_DIR); $BRDFD_BINARY
// overrides the path.
#pragma once

#include <sys/types.h>

#include <chrono>
#include <memory>
#include <string>
#include <vector>

#include "core/status.h"
#include "tests/support/process_launcher.h"

namespace brdf::testing {

Result<std::string> BrdfdBinary();

// The resident memory (VmRSS) of process `pid`, kB, from /proc; -1 when it cannot be read (the
// process is gone).
long ResidentKb(pid_t pid);

class DaemonProcess {
 public:
  // Starts brdfd with `args` (e.g. {"--config", path}); its log is appended to `log_path`.
  // Waits up to `timeout` for the "listening" line. On failure the child is killed and the error
  // carries the end of its log.
  static Result<std::unique_ptr<DaemonProcess>> Start(
      const std::vector<std::string>& args, const std::string& log_path,
      std::chrono::milliseconds timeout = std::chrono::seconds(15));

  ~DaemonProcess();  // SIGKILL if still running
  DaemonProcess(const DaemonProcess&) = delete;
  DaemonProcess& operator=(const DaemonProcess&) = delete;

  // "127.0.0.1:43123", as brdfd printed it.
  const std::string& address() const { return address_; }
  pid_t pid() const { return child_ ? child_->pid() : -1; }

  // SIGTERM, then waits up to `timeout`; the exit code (128 + signal when killed by one).
  // kTimeout (after a SIGKILL) when it did not exit in time.
  Result<int> Stop(std::chrono::milliseconds timeout = std::chrono::seconds(20));
  // SIGKILL and reap: the daemon dies as in a power cut (no shutdown code runs).
  void Kill();

  // The last `max_bytes` of the daemon's log (for failure messages).
  std::string log(std::size_t max_bytes = 6000) const;

 private:
  DaemonProcess() = default;

  std::unique_ptr<ChildProcess> child_;
  std::string address_;
  std::string log_path_;
};

// Runs brdfd to completion (e.g. with a bad configuration) within `timeout`: exit code and what
// it wrote to stderr.
struct DaemonRun {
  int exit_code = 0;
  std::string err;
};
Result<DaemonRun> RunBrdfd(const std::vector<std::string>& args, const std::string& log_path,
                           std::chrono::milliseconds timeout = std::chrono::seconds(15));

}  // namespace brdf::testing
