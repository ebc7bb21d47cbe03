// Runs the built brdf-sim as a child process for tests: starts it with flags, waits for its
// start-up lines (pr650 …, modbus-tcp …, [modbus-rtu …,] control-unit …, ready), exposes the
// endpoints it printed, and stops it (SIGTERM, then SIGKILL) when the object goes away.
//
// The binary is $BRDF_BUILD_DIR/tools/brdf-sim/brdf-sim (brdf_add_test sets BRDF_BUILD_DIR);
// $BRDF_SIM_BINARY overrides the path.
#pragma once

#include <sys/types.h>

#include <chrono>
#include <memory>
#include <string>
#include <vector>

#include "core/status.h"
#include "tests/support/process_launcher.h"

namespace brdf::testing {

// Where the brdf-sim executable is, or why it cannot be found.
Result<std::string> BrdfSimBinary();

class SimProcess {
 public:
  // Starts brdf-sim with `args` (without the program name) and waits up to `timeout` for "ready".
  // On failure the child is stopped and the error says which lines it printed before.
  static Result<std::unique_ptr<SimProcess>> Start(
      const std::vector<std::string>& args,
      std::chrono::milliseconds timeout = std::chrono::seconds(15));

  ~SimProcess();
  SimProcess(const SimProcess&) = delete;
  SimProcess& operator=(const SimProcess&) = delete;

  // The meter's port, whichever meter it is (--meter; the line is named after it).
  const std::string& pr650_path() const { return pr650_path_; }
  const std::string& meter_path() const { return pr650_path_; }
  const std::string& meter() const { return meter_; }  // "pr650", "pr670", "cs2000", ...
  const std::string& modbus_host() const { return modbus_host_; }
  int modbus_port() const { return modbus_port_; }
  const std::string& rtu_path() const { return rtu_path_; }  // empty without --rtu
  int control_unit() const { return control_unit_; }
  // Every line printed before (and including) "ready", in order.
  const std::vector<std::string>& startup_lines() const { return lines_; }
  pid_t pid() const { return child_ ? child_->pid() : -1; }

  // Sends SIGTERM and waits up to `timeout` for the exit; returns the exit code (128 + signal
  // number when killed by a signal). After the timeout the child is killed and the result is
  // kTimeout. Called by the destructor if not called before.
  Result<int> Stop(std::chrono::milliseconds timeout = std::chrono::seconds(5));

 private:
  SimProcess() = default;
  Status ParseLine(const std::string& line);

  std::unique_ptr<ChildProcess> child_;
  std::string pr650_path_;
  std::string meter_ = "pr650";
  std::string modbus_host_;
  int modbus_port_ = 0;
  std::string rtu_path_;
  int control_unit_ = 0;
  std::vector<std::string> lines_;
};

// Runs brdf-sim with `args` to completion (for subcommands like `truth`), within `timeout`.
Result<CommandResult> RunBrdfSim(const std::vector<std::string>& args,
                                 std::chrono::milliseconds timeout = std::chrono::seconds(15));

}  // namespace brdf::testing
