#include "tests/support/process_launcher.h"

#include <fcntl.h>
#include <poll.h>
#include <signal.h>
#include <sys/prctl.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <cstdlib>
#include <cstring>
#include <thread>

extern char** environ;

namespace brdf::testing {
namespace {

using Clock = std::chrono::steady_clock;

int ExitCodeOf(int wait_status) {
  if (WIFEXITED(wait_status)) return WEXITSTATUS(wait_status);
  if (WIFSIGNALED(wait_status)) return 128 + WTERMSIG(wait_status);
  return -1;
}

int RemainingMs(Clock::time_point deadline) {
  const auto left =
      std::chrono::duration_cast<std::chrono::milliseconds>(deadline - Clock::now()).count();
  return left < 0 ? 0 : static_cast<int>(left);
}

void CloseBoth(int fds[2]) {
  for (int i = 0; i < 2; ++i) {
    if (fds[i] >= 0) ::close(fds[i]);
    fds[i] = -1;
  }
}

}  // namespace

Result<std::string> BuiltProgram(const std::string& name, const std::string& relative_path,
                                 const char* override_env, const char* fallback_build_dir) {
  std::string path;
  if (const char* explicit_path = std::getenv(override_env); explicit_path && *explicit_path) {
    path = explicit_path;
  } else if (const char* build = std::getenv("BRDF_BUILD_DIR"); build && *build) {
    path = std::string(build) + "/" + relative_path;
  } else if (fallback_build_dir != nullptr) {
    path = std::string(fallback_build_dir) + "/" + relative_path;
  } else {
    return FailedPrecondition("cannot find " + name +
                              ": BRDF_BUILD_DIR is not set; run the test through ctest (which "
                              "sets it) or set BRDF_BUILD_DIR to the build directory (or " +
                              override_env + " to the program)");
  }
  if (::access(path.c_str(), X_OK) != 0) {
    return NotFound(name + " is not at " + path + " (" + std::strerror(errno) +
                    "); build it first: cmake --build <build dir> --target " + name);
  }
  return path;
}

Result<std::unique_ptr<ChildProcess>> ChildProcess::Launch(const std::string& what,
                                                           const std::string& binary,
                                                           const LaunchOptions& options) {
  using Stderr = LaunchOptions::Stderr;
  int out_pipe[2] = {-1, -1};
  int err_pipe[2] = {-1, -1};
  if (::pipe2(out_pipe, O_CLOEXEC) != 0 ||
      (options.stderr_to == Stderr::kPipe && ::pipe2(err_pipe, O_CLOEXEC) != 0)) {
    const std::string why = std::strerror(errno);
    CloseBoth(out_pipe);
    return IoError("cannot create a pipe for " + what + ": " + why);
  }
  int log_fd = -1;
  if (options.stderr_to == Stderr::kAppendToFile) {
    log_fd = ::open(options.stderr_path.c_str(), O_WRONLY | O_CREAT | O_APPEND | O_CLOEXEC, 0644);
    if (log_fd < 0) {
      const std::string why = std::strerror(errno);
      CloseBoth(out_pipe);
      return IoError("cannot open the log file " + options.stderr_path + ": " + why);
    }
  }
  // Everything the child needs is built before fork: only async-signal-safe calls after it.
  std::vector<std::string> argv_strings = {binary};
  argv_strings.insert(argv_strings.end(), options.args.begin(), options.args.end());
  std::vector<char*> argv;
  for (std::string& s : argv_strings) argv.push_back(s.data());
  argv.push_back(nullptr);
  const bool own_env = !options.unset_env.empty() || !options.set_env.empty();
  std::vector<std::string> env_strings;
  if (own_env) {
    for (char** e = environ; *e != nullptr; ++e) {
      const std::string entry = *e;
      const bool unset = std::any_of(
          options.unset_env.begin(), options.unset_env.end(),
          [&entry](const std::string& name) { return entry.rfind(name + "=", 0) == 0; });
      if (!unset) env_strings.push_back(entry);
    }
    for (const auto& [name, value] : options.set_env) env_strings.push_back(name + "=" + value);
  }
  std::vector<char*> envp;
  for (std::string& s : env_strings) envp.push_back(s.data());
  envp.push_back(nullptr);
  const pid_t parent = ::getpid();

  const pid_t pid = ::fork();
  if (pid < 0) {
    const std::string why = std::strerror(errno);
    CloseBoth(out_pipe);
    CloseBoth(err_pipe);
    if (log_fd >= 0) ::close(log_fd);
    return IoError("cannot fork to start " + what + ": " + why);
  }
  if (pid == 0) {
    ::prctl(PR_SET_PDEATHSIG, SIGKILL);
    if (::getppid() != parent) ::_exit(126);
    if (options.stdin_from_null) {
      const int null_fd = ::open("/dev/null", O_RDONLY);
      ::dup2(null_fd, STDIN_FILENO);
    }
    ::dup2(out_pipe[1], STDOUT_FILENO);
    if (err_pipe[1] >= 0) ::dup2(err_pipe[1], STDERR_FILENO);
    if (log_fd >= 0) ::dup2(log_fd, STDERR_FILENO);
    if (options.stdout_with_stderr) ::dup2(STDERR_FILENO, STDOUT_FILENO);
    if (own_env) {
      if (options.search_path) {
        ::execvpe(argv[0], argv.data(), envp.data());
      } else {
        ::execve(argv[0], argv.data(), envp.data());
      }
    } else if (options.search_path) {
      ::execvp(argv[0], argv.data());
    } else {
      ::execv(argv[0], argv.data());
    }
    ::_exit(127);
  }
  std::unique_ptr<ChildProcess> child(new ChildProcess());
  child->what_ = what;
  child->pid_ = pid;
  ::close(out_pipe[1]);
  child->out_fd_ = out_pipe[0];
  if (err_pipe[1] >= 0) {
    ::close(err_pipe[1]);
    child->err_fd_ = err_pipe[0];
  }
  if (log_fd >= 0) ::close(log_fd);
  return child;
}

ChildProcess::~ChildProcess() {
  Kill();
  if (out_fd_ >= 0) ::close(out_fd_);
  if (err_fd_ >= 0) ::close(err_fd_);
}

Result<std::string> ChildProcess::ReadLine(TimePoint deadline) {
  for (;;) {
    const std::size_t nl = pending_.find('\n');
    if (nl != std::string::npos) {
      std::string line = pending_.substr(0, nl);
      pending_.erase(0, nl + 1);
      return line;
    }
    pollfd pfd{out_fd_, POLLIN, 0};
    const int ready = ::poll(&pfd, 1, RemainingMs(deadline));
    if (ready < 0 && errno == EINTR) continue;
    if (ready <= 0) return Timeout(what_ + " printed no line in time");
    char buf[1024];
    const ssize_t n = ::read(out_fd_, buf, sizeof buf);
    if (n < 0 && errno == EINTR) continue;
    if (n <= 0) return IoError(what_ + " closed its output");
    pending_.append(buf, static_cast<std::size_t>(n));
  }
}

bool ChildProcess::ReadAll(TimePoint deadline, std::string& out, std::string& err) {
  out += pending_;
  pending_.clear();
  bool open[2] = {out_fd_ >= 0, err_fd_ >= 0};
  const int fds[2] = {out_fd_, err_fd_};
  while ((open[0] || open[1]) && Clock::now() < deadline) {
    pollfd pfds[2] = {{open[0] ? fds[0] : -1, POLLIN, 0}, {open[1] ? fds[1] : -1, POLLIN, 0}};
    const int ready = ::poll(pfds, 2, RemainingMs(deadline));
    if (ready < 0 && errno == EINTR) continue;
    if (ready <= 0) break;
    for (int i = 0; i < 2; ++i) {
      if (pfds[i].fd < 0 || pfds[i].revents == 0) continue;
      char buf[8192];
      const ssize_t n = ::read(pfds[i].fd, buf, sizeof buf);
      if (n > 0) {
        (i == 0 ? out : err).append(buf, static_cast<std::size_t>(n));
      } else if (n == 0 || errno != EINTR) {
        open[i] = false;
      }
    }
  }
  return !open[0] && !open[1];
}

std::optional<int> ChildProcess::WaitUntil(TimePoint deadline) {
  if (pid_ <= 0) return std::nullopt;
  for (;;) {
    int status = 0;
    const pid_t r = ::waitpid(pid_, &status, WNOHANG);
    if (r == pid_) {
      pid_ = -1;
      return ExitCodeOf(status);
    }
    if (r < 0 && errno != EINTR) {
      pid_ = -1;
      return -1;
    }
    if (Clock::now() >= deadline) return std::nullopt;
    std::this_thread::sleep_for(std::chrono::milliseconds(5));
  }
}

std::optional<int> ChildProcess::Terminate(std::chrono::milliseconds timeout) {
  if (pid_ <= 0) return std::nullopt;
  ::kill(pid_, SIGTERM);
  std::optional<int> code = WaitUntil(Clock::now() + timeout);
  if (!code) Kill();
  return code;
}

void ChildProcess::Kill() {
  if (pid_ <= 0) return;
  ::kill(pid_, SIGKILL);
  (void)WaitUntil(Clock::now() + std::chrono::seconds(5));
  pid_ = -1;
}

Result<CommandResult> RunToCompletion(const std::string& what, const std::string& binary,
                                      LaunchOptions options, std::chrono::milliseconds timeout,
                                      CommandResult* partial) {
  if (options.stderr_to == LaunchOptions::Stderr::kInherit) {
    options.stderr_to = LaunchOptions::Stderr::kPipe;
  }
  BRDF_ASSIGN_OR_RETURN(std::unique_ptr<ChildProcess> child,
                        ChildProcess::Launch(what, binary, options));
  const auto deadline = Clock::now() + timeout;
  CommandResult result;
  child->ReadAll(deadline, result.out, result.err);
  std::optional<int> code = child->WaitUntil(deadline);
  if (!code) {
    child->Kill();
    if (partial != nullptr) *partial = result;
    return Timeout(what + " did not finish within " + std::to_string(timeout.count()) + " ms");
  }
  result.exit_code = *code;
  return result;
}

}  // namespace brdf::testing
