#include "tests/daemon/daemon_process.h"

#include <fcntl.h>
#include <poll.h>
#include <signal.h>
#include <sys/prctl.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cerrno>
#include <cstdlib>
#include <cstring>
#include <fstream>
#include <optional>
#include <sstream>
#include <thread>

namespace brdf::testing {
namespace {

using Clock = std::chrono::steady_clock;
constexpr std::string_view kListening = "brdfd listening on ";

int ExitCodeOf(int wait_status) {
  if (WIFEXITED(wait_status)) return WEXITSTATUS(wait_status);
  if (WIFSIGNALED(wait_status)) return 128 + WTERMSIG(wait_status);
  return -1;
}

std::optional<int> WaitUntil(pid_t pid, Clock::time_point deadline) {
  for (;;) {
    int status = 0;
    const pid_t r = ::waitpid(pid, &status, WNOHANG);
    if (r == pid) return ExitCodeOf(status);
    if (r < 0 && errno != EINTR) return -1;
    if (Clock::now() >= deadline) return std::nullopt;
    std::this_thread::sleep_for(std::chrono::milliseconds(5));
  }
}

// Forks and execs brdfd: stdout to a new pipe, stderr appended to `log_path`. The child dies
// with the test (PR_SET_PDEATHSIG).
Result<pid_t> Spawn(const std::string& binary, const std::vector<std::string>& args,
                    const std::string& log_path, int* out_fd) {
  int out_pipe[2] = {-1, -1};
  if (::pipe2(out_pipe, O_CLOEXEC) != 0) {
    return IoError(std::string("cannot create a pipe for brdfd: ") + std::strerror(errno));
  }
  const int log_fd = ::open(log_path.c_str(), O_WRONLY | O_CREAT | O_APPEND | O_CLOEXEC, 0644);
  if (log_fd < 0) {
    ::close(out_pipe[0]);
    ::close(out_pipe[1]);
    return IoError("cannot open the log file " + log_path + ": " + std::strerror(errno));
  }
  std::vector<char*> argv;
  argv.push_back(const_cast<char*>(binary.c_str()));
  for (const auto& a : args) argv.push_back(const_cast<char*>(a.c_str()));
  argv.push_back(nullptr);
  const pid_t parent = ::getpid();

  const pid_t pid = ::fork();
  if (pid < 0) {
    ::close(log_fd);
    return IoError(std::string("cannot fork to start brdfd: ") + std::strerror(errno));
  }
  if (pid == 0) {
    ::prctl(PR_SET_PDEATHSIG, SIGKILL);
    if (::getppid() != parent) ::_exit(126);
    ::dup2(out_pipe[1], STDOUT_FILENO);
    ::dup2(log_fd, STDERR_FILENO);
    ::execv(binary.c_str(), argv.data());
    ::_exit(127);
  }
  ::close(out_pipe[1]);
  ::close(log_fd);
  *out_fd = out_pipe[0];
  return pid;
}

std::string Tail(const std::string& path, std::size_t max_bytes) {
  std::ifstream in(path, std::ios::binary);
  std::ostringstream text;
  text << in.rdbuf();
  std::string s = text.str();
  if (s.size() > max_bytes) s = "…" + s.substr(s.size() - max_bytes);
  return s;
}

}  // namespace

Result<std::string> BrdfdBinary() {
  std::string path;
  if (const char* explicit_path = std::getenv("BRDFD_BINARY"); explicit_path && *explicit_path) {
    path = explicit_path;
  } else if (const char* build = std::getenv("BRDF_BUILD_DIR"); build && *build) {
    path = std::string(build) + "/daemon/brdfd";
  } else {
    return FailedPrecondition(
        "cannot find brdfd: BRDF_BUILD_DIR is not set; run the test through ctest (which sets "
        "it) or set BRDFD_BINARY");
  }
  if (::access(path.c_str(), X_OK) != 0) {
    return NotFound("brdfd is not at " + path + " (" + std::strerror(errno) +
                    "); build it first: cmake --build <build dir> --target brdfd");
  }
  return path;
}

Result<std::unique_ptr<DaemonProcess>> DaemonProcess::Start(const std::vector<std::string>& args,
                                                            const std::string& log_path,
                                                            std::chrono::milliseconds timeout) {
  Result<std::string> binary = BrdfdBinary();
  if (!binary.ok()) return binary.status();
  std::unique_ptr<DaemonProcess> d(new DaemonProcess());
  d->log_path_ = log_path;
  Result<pid_t> pid = Spawn(*binary, args, log_path, &d->stdout_fd_);
  if (!pid.ok()) return pid.status();
  d->pid_ = *pid;

  const auto deadline = Clock::now() + timeout;
  std::string pending;
  for (;;) {
    const std::size_t nl = pending.find('\n');
    if (nl != std::string::npos) {
      const std::string line = pending.substr(0, nl);
      pending.erase(0, nl + 1);
      if (line.rfind(kListening, 0) == 0) {
        d->address_ = line.substr(kListening.size());
        return d;
      }
      return ProtocolError("brdfd printed an unexpected line \"" + line + "\"; log:\n" + d->log());
    }
    const auto left =
        std::chrono::duration_cast<std::chrono::milliseconds>(deadline - Clock::now());
    pollfd pfd{d->stdout_fd_, POLLIN, 0};
    const int ready = ::poll(&pfd, 1, static_cast<int>(std::max<long>(0, left.count())));
    if (ready < 0 && errno == EINTR) continue;
    if (ready <= 0) {
      return Timeout("brdfd did not print \"brdfd listening on …\" within " +
                     std::to_string(timeout.count()) + " ms; log:\n" + d->log());
    }
    char buf[512];
    const ssize_t n = ::read(d->stdout_fd_, buf, sizeof buf);
    if (n < 0 && errno == EINTR) continue;
    if (n <= 0) {
      std::optional<int> code = WaitUntil(d->pid_, Clock::now() + std::chrono::seconds(2));
      if (code) d->pid_ = -1;
      return Internal("brdfd exited during start-up" +
                      (code ? " with code " + std::to_string(*code) : std::string()) + "; log:\n" +
                      d->log());
    }
    pending.append(buf, static_cast<std::size_t>(n));
  }
}

DaemonProcess::~DaemonProcess() {
  Kill();
  if (stdout_fd_ >= 0) ::close(stdout_fd_);
}

Result<int> DaemonProcess::Stop(std::chrono::milliseconds timeout) {
  if (pid_ <= 0) return Internal("brdfd was already stopped");
  ::kill(pid_, SIGTERM);
  std::optional<int> code = WaitUntil(pid_, Clock::now() + timeout);
  if (!code) {
    Kill();
    return Timeout("brdfd did not exit within " + std::to_string(timeout.count()) +
                   " ms of SIGTERM; killed it. Log:\n" + log());
  }
  pid_ = -1;
  return *code;
}

void DaemonProcess::Kill() {
  if (pid_ <= 0) return;
  ::kill(pid_, SIGKILL);
  WaitUntil(pid_, Clock::now() + std::chrono::seconds(5));
  pid_ = -1;
}

std::string DaemonProcess::log(std::size_t max_bytes) const {
  return Tail(log_path_, max_bytes);
}

Result<DaemonRun> RunBrdfd(const std::vector<std::string>& args, const std::string& log_path,
                           std::chrono::milliseconds timeout) {
  Result<std::string> binary = BrdfdBinary();
  if (!binary.ok()) return binary.status();
  int out_fd = -1;
  Result<pid_t> pid = Spawn(*binary, args, log_path, &out_fd);
  if (!pid.ok()) return pid.status();
  std::optional<int> code = WaitUntil(*pid, Clock::now() + timeout);
  ::close(out_fd);
  if (!code) {
    ::kill(*pid, SIGKILL);
    WaitUntil(*pid, Clock::now() + std::chrono::seconds(5));
    return Timeout("brdfd did not exit within " + std::to_string(timeout.count()) + " ms");
  }
  return DaemonRun{*code, Tail(log_path, 100000)};
}

}  // namespace brdf::testing
