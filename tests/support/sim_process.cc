#include "tests/support/sim_process.h"

#include <fcntl.h>
#include <poll.h>
#include <signal.h>
#include <sys/prctl.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cerrno>
#include <cstdlib>
#include <cstring>
#include <thread>

namespace brdf::testing {
namespace {

using Clock = std::chrono::steady_clock;

std::string Join(const std::vector<std::string>& lines) {
  std::string out;
  for (const auto& l : lines) out += (out.empty() ? "" : " | ") + l;
  return out.empty() ? "(nothing)" : out;
}

int ExitCodeOf(int wait_status) {
  if (WIFEXITED(wait_status)) return WEXITSTATUS(wait_status);
  if (WIFSIGNALED(wait_status)) return 128 + WTERMSIG(wait_status);
  return -1;
}

// Forks and execs `binary` with `args`; the child's stdout (and stderr when `err_fd` is given)
// go to new pipes. The child dies with the test process (PR_SET_PDEATHSIG).
Result<pid_t> Spawn(const std::string& binary, const std::vector<std::string>& args, int* out_fd,
                    int* err_fd) {
  int out_pipe[2] = {-1, -1};
  int err_pipe[2] = {-1, -1};
  if (::pipe2(out_pipe, O_CLOEXEC) != 0 ||
      (err_fd != nullptr && ::pipe2(err_pipe, O_CLOEXEC) != 0)) {
    return IoError(std::string("cannot create a pipe for brdf-sim: ") + std::strerror(errno));
  }
  // Everything the child needs is built before fork: only async-signal-safe calls after it.
  std::vector<char*> argv;
  argv.push_back(const_cast<char*>(binary.c_str()));
  for (const auto& a : args) argv.push_back(const_cast<char*>(a.c_str()));
  argv.push_back(nullptr);
  const pid_t parent = ::getpid();

  const pid_t pid = ::fork();
  if (pid < 0) {
    return IoError(std::string("cannot fork to start brdf-sim: ") + std::strerror(errno));
  }
  if (pid == 0) {
    ::prctl(PR_SET_PDEATHSIG, SIGKILL);
    if (::getppid() != parent) ::_exit(126);
    ::dup2(out_pipe[1], STDOUT_FILENO);
    if (err_fd != nullptr) ::dup2(err_pipe[1], STDERR_FILENO);
    ::execv(binary.c_str(), argv.data());
    ::_exit(127);
  }
  ::close(out_pipe[1]);
  *out_fd = out_pipe[0];
  if (err_fd != nullptr) {
    ::close(err_pipe[1]);
    *err_fd = err_pipe[0];
  }
  return pid;
}

// Waits for `pid` until `deadline`; the exit code, or nullopt on timeout.
std::optional<int> WaitUntil(pid_t pid, Clock::time_point deadline) {
  while (true) {
    int status = 0;
    const pid_t r = ::waitpid(pid, &status, WNOHANG);
    if (r == pid) return ExitCodeOf(status);
    if (r < 0 && errno != EINTR) return -1;
    if (Clock::now() >= deadline) return std::nullopt;
    std::this_thread::sleep_for(std::chrono::milliseconds(5));
  }
}

int RemainingMs(Clock::time_point deadline) {
  const auto left =
      std::chrono::duration_cast<std::chrono::milliseconds>(deadline - Clock::now()).count();
  return left < 0 ? 0 : static_cast<int>(left);
}

}  // namespace

Result<std::string> BrdfSimBinary() {
  std::string path;
  if (const char* explicit_path = std::getenv("BRDF_SIM_BINARY"); explicit_path && *explicit_path) {
    path = explicit_path;
  } else if (const char* build = std::getenv("BRDF_BUILD_DIR"); build && *build) {
    path = std::string(build) + "/tools/brdf-sim/brdf-sim";
  } else {
    return FailedPrecondition(
        "cannot find brdf-sim: BRDF_BUILD_DIR is not set; run the test through ctest (which sets "
        "it) or set BRDF_BUILD_DIR to the build directory");
  }
  if (::access(path.c_str(), X_OK) != 0) {
    return NotFound("brdf-sim is not at " + path + " (" + std::strerror(errno) +
                    "); build it first: cmake --build <build dir> --target brdf-sim");
  }
  return path;
}

Result<std::unique_ptr<SimProcess>> SimProcess::Start(const std::vector<std::string>& args,
                                                      std::chrono::milliseconds timeout) {
  auto binary = BrdfSimBinary();
  if (!binary.ok()) return binary.status();

  std::unique_ptr<SimProcess> sim(new SimProcess());
  auto pid = Spawn(*binary, args, &sim->stdout_fd_, nullptr);
  if (!pid.ok()) return pid.status();
  sim->pid_ = *pid;

  const auto deadline = Clock::now() + timeout;
  std::string pending;
  while (true) {
    const std::size_t nl = pending.find('\n');
    if (nl != std::string::npos) {
      std::string line = pending.substr(0, nl);
      pending.erase(0, nl + 1);
      if (!line.empty() && line.back() == '\r') line.pop_back();
      sim->lines_.push_back(line);
      if (Status s = sim->ParseLine(line); !s.ok()) {
        return s.WithContext("brdf-sim start-up (printed so far: " + Join(sim->lines_) + ")");
      }
      if (line == "ready") return sim;
      continue;
    }
    pollfd pfd{sim->stdout_fd_, POLLIN, 0};
    const int ready = ::poll(&pfd, 1, RemainingMs(deadline));
    if (ready < 0 && errno == EINTR) continue;
    if (ready <= 0) {
      return Timeout("brdf-sim did not print 'ready' within " + std::to_string(timeout.count()) +
                     " ms (printed: " + Join(sim->lines_) + "); see its log on stderr");
    }
    char buf[1024];
    const ssize_t n = ::read(sim->stdout_fd_, buf, sizeof buf);
    if (n < 0 && errno == EINTR) continue;
    if (n <= 0) {
      auto code = WaitUntil(sim->pid_, Clock::now() + std::chrono::seconds(2));
      if (code) sim->pid_ = -1;
      return Internal("brdf-sim exited during start-up" +
                      (code ? " with code " + std::to_string(*code) : std::string()) +
                      " (printed: " + Join(sim->lines_) + "); see its log on stderr");
    }
    pending.append(buf, static_cast<std::size_t>(n));
  }
}

Status SimProcess::ParseLine(const std::string& line) {
  const std::size_t space = line.find(' ');
  const std::string key = line.substr(0, space);
  const std::string value = space == std::string::npos ? "" : line.substr(space + 1);
  if (key == "pr650" && !value.empty()) {
    pr650_path_ = value;
  } else if (key == "modbus-tcp") {
    const std::size_t colon = value.rfind(':');
    if (colon == std::string::npos || colon == 0) {
      return ProtocolError("'modbus-tcp' line is not <host>:<port>: " + line);
    }
    modbus_host_ = value.substr(0, colon);
    char* end = nullptr;
    const long port = std::strtol(value.c_str() + colon + 1, &end, 10);
    if (*end != '\0' || port <= 0 || port > 65535) {
      return ProtocolError("'modbus-tcp' line has no valid port: " + line);
    }
    modbus_port_ = static_cast<int>(port);
  } else if (key == "modbus-rtu" && !value.empty()) {
    rtu_path_ = value;
  } else if (key == "control-unit") {
    control_unit_ = std::atoi(value.c_str());
    if (control_unit_ <= 0 || control_unit_ > 247) {
      return ProtocolError("'control-unit' line has no valid unit id: " + line);
    }
  } else if (line == "ready") {
    if (pr650_path_.empty() || modbus_port_ == 0 || control_unit_ == 0) {
      return ProtocolError("'ready' came before the pr650, modbus-tcp and control-unit lines");
    }
  } else {
    return ProtocolError("unexpected start-up line '" + line +
                         "' (the contract is in tools/brdf-sim/README.md)");
  }
  return Status::Ok();
}

Result<int> SimProcess::Stop(std::chrono::milliseconds timeout) {
  if (pid_ <= 0) return Internal("brdf-sim was already stopped");
  ::kill(pid_, SIGTERM);
  auto code = WaitUntil(pid_, Clock::now() + timeout);
  if (!code) {
    ::kill(pid_, SIGKILL);
    WaitUntil(pid_, Clock::now() + std::chrono::seconds(5));
    pid_ = -1;
    return Timeout("brdf-sim did not exit within " + std::to_string(timeout.count()) +
                   " ms of SIGTERM; killed it");
  }
  pid_ = -1;
  return *code;
}

SimProcess::~SimProcess() {
  if (pid_ > 0) (void)Stop();
  if (stdout_fd_ >= 0) ::close(stdout_fd_);
}

Result<CommandResult> RunBrdfSim(const std::vector<std::string>& args,
                                 std::chrono::milliseconds timeout) {
  auto binary = BrdfSimBinary();
  if (!binary.ok()) return binary.status();
  int out_fd = -1;
  int err_fd = -1;
  auto pid = Spawn(*binary, args, &out_fd, &err_fd);
  if (!pid.ok()) return pid.status();

  CommandResult result;
  const auto deadline = Clock::now() + timeout;
  bool out_open = true;
  bool err_open = true;
  while ((out_open || err_open) && Clock::now() < deadline) {
    pollfd pfds[2] = {{out_open ? out_fd : -1, POLLIN, 0}, {err_open ? err_fd : -1, POLLIN, 0}};
    const int ready = ::poll(pfds, 2, RemainingMs(deadline));
    if (ready < 0 && errno == EINTR) continue;
    if (ready <= 0) break;
    for (int i = 0; i < 2; ++i) {
      if (pfds[i].fd < 0 || pfds[i].revents == 0) continue;
      char buf[4096];
      const ssize_t n = ::read(pfds[i].fd, buf, sizeof buf);
      if (n > 0) {
        (i == 0 ? result.out : result.err).append(buf, static_cast<std::size_t>(n));
      } else if (n == 0 || errno != EINTR) {
        (i == 0 ? out_open : err_open) = false;
      }
    }
  }
  ::close(out_fd);
  ::close(err_fd);
  auto code = WaitUntil(*pid, deadline);
  if (!code) {
    ::kill(*pid, SIGKILL);
    WaitUntil(*pid, Clock::now() + std::chrono::seconds(5));
    return Timeout("brdf-sim did not finish within " + std::to_string(timeout.count()) + " ms");
  }
  result.exit_code = *code;
  return result;
}

}  // namespace brdf::testing
