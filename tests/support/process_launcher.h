// Starts the programs the tests run as child processes (brdf-sim, brdfd, brdfctl, …) in one way:
// fork and exec with the arguments, stdout to a pipe the test reads, stderr to a pipe, to the
// test's own stderr or appended to a log file, optionally a changed environment and standard
// input from /dev/null. The child dies with the test process (PR_SET_PDEATHSIG). Program-specific
// start-up contracts (brdf-sim's endpoint lines, brdfd's "listening" line) live in their own
// wrappers (sim/process.h, tests/support/daemon/process.h, tests/brdfctl/ctl_runner.h).
#pragma once

#include <sys/types.h>

#include <chrono>
#include <memory>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "core/status.h"

namespace brdf::testing {

// What a short-lived command printed.
struct CommandResult {
  int exit_code = 0;  // 128 + signal number when killed by a signal
  std::string out;
  std::string err;
};

// Environment entries ("NAME", "value").
using EnvVars = std::vector<std::pair<std::string, std::string>>;

// Where a built program is: $`override_env` when set, else $BRDF_BUILD_DIR/`relative_path`
// (brdf_add_test sets BRDF_BUILD_DIR), else `fallback_build_dir`/`relative_path` when given.
// `name` is for the messages ("brdf-sim"), and names the target to build when it is missing.
Result<std::string> BuiltProgram(const std::string& name, const std::string& relative_path,
                                 const char* override_env,
                                 const char* fallback_build_dir = nullptr);

struct LaunchOptions {
  LaunchOptions() = default;
  explicit LaunchOptions(std::vector<std::string> program_args) : args(std::move(program_args)) {}

  std::vector<std::string> args;  // without the program name
  enum class Stderr { kInherit, kPipe, kAppendToFile };
  Stderr stderr_to = Stderr::kInherit;
  std::string stderr_path;          // with kAppendToFile
  bool stdout_with_stderr = false;  // stdout goes where stderr goes (e.g. the same log file)
  bool stdin_from_null = false;
  bool search_path = false;  // the binary is a name looked up on $PATH (execvp)
  // The environment: the test's own, less `unset_env` (names), plus `set_env`.
  std::vector<std::string> unset_env;
  EnvVars set_env;
};

class ChildProcess {
 public:
  using TimePoint = std::chrono::steady_clock::time_point;

  // Starts `binary`; `what` names it in messages ("brdf-sim").
  static Result<std::unique_ptr<ChildProcess>> Launch(const std::string& what,
                                                      const std::string& binary,
                                                      const LaunchOptions& options);
  ~ChildProcess();  // SIGKILL and reap if still running
  ChildProcess(const ChildProcess&) = delete;
  ChildProcess& operator=(const ChildProcess&) = delete;

  pid_t pid() const { return pid_; }
  bool running() const { return pid_ > 0; }

  // The next line the child printed on stdout (without "\n"), waiting until `deadline`:
  // kTimeout then, kIoError when stdout closed first (the child exited).
  Result<std::string> ReadLine(TimePoint deadline);
  // Reads stdout (and stderr, when piped) into `out`/`err` until both close or `deadline`.
  // True when both closed.
  bool ReadAll(TimePoint deadline, std::string& out, std::string& err);

  // Waits for the exit until `deadline`: the exit code (128 + signal), nullopt on timeout.
  std::optional<int> WaitUntil(TimePoint deadline);
  // SIGTERM, then waits up to `timeout`; the exit code. After the timeout: SIGKILL, and nullopt.
  std::optional<int> Terminate(std::chrono::milliseconds timeout);
  // SIGKILL and reap (no-op when it has exited).
  void Kill();
  // Forget the child without signalling it (it was reaped elsewhere).
  void Release() { pid_ = -1; }

 private:
  ChildProcess() = default;

  std::string what_;
  pid_t pid_ = -1;
  int out_fd_ = -1;
  int err_fd_ = -1;
  std::string pending_;  // stdout read past the last line returned
};

// Runs `binary` to completion within `timeout`, reading what it prints. kTimeout (the child
// killed) when it did not finish; `partial` then holds what it printed.
Result<CommandResult> RunToCompletion(const std::string& what, const std::string& binary,
                                      LaunchOptions options, std::chrono::milliseconds timeout,
                                      CommandResult* partial = nullptr);

}  // namespace brdf::testing
