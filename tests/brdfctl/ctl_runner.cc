#include "tests/brdfctl/ctl_runner.h"

#include <fcntl.h>
#include <poll.h>
#include <signal.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cerrno>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <sstream>

extern char** environ;

namespace brdf::testing {
namespace {

using Clock = std::chrono::steady_clock;

int RemainingMs(Clock::time_point deadline) {
  const auto left = std::chrono::duration_cast<std::chrono::milliseconds>(deadline - Clock::now());
  return left.count() > 0 ? static_cast<int>(left.count()) : 0;
}

int ExitCode(int status) {
  return WIFEXITED(status) ? WEXITSTATUS(status) : 128 + WTERMSIG(status);
}

}  // namespace

Result<std::string> BrdfctlBinary() {
  if (const char* path = std::getenv("BRDFCTL_BINARY")) return std::string(path);
  const char* build = std::getenv("BRDF_BUILD_DIR");
#ifdef BRDF_TEST_BUILD_DIR
  if (build == nullptr) build = BRDF_TEST_BUILD_DIR;
#endif
  if (build == nullptr) {
    return NotFound("BRDF_BUILD_DIR is not set; run the test through ctest or set BRDFCTL_BINARY");
  }
  const std::string path = std::string(build) + "/tools/brdfctl/brdfctl";
  if (!std::filesystem::exists(path)) {
    return NotFound(path + " does not exist; build the brdfctl target first");
  }
  return path;
}

Result<CommandResult> RunBrdfctl(const std::vector<std::string>& args, const EnvVars& env,
                                 std::chrono::milliseconds timeout) {
  Result<std::string> binary = BrdfctlBinary();
  if (!binary.ok()) return binary.status();

  // Everything the child needs is built before fork().
  std::vector<std::string> argv_strings = {*binary};
  argv_strings.insert(argv_strings.end(), args.begin(), args.end());
  std::vector<char*> argv;
  for (std::string& s : argv_strings) argv.push_back(s.data());
  argv.push_back(nullptr);
  std::vector<std::string> env_strings;
  for (char** e = environ; *e != nullptr; ++e) {
    const std::string entry = *e;
    if (entry.rfind("BRDF_ADDRESS=", 0) == 0 || entry.rfind("BRDF_TOKEN=", 0) == 0) continue;
    env_strings.push_back(entry);
  }
  for (const auto& [name, value] : env) env_strings.push_back(name + "=" + value);
  std::vector<char*> envp;
  for (std::string& s : env_strings) envp.push_back(s.data());
  envp.push_back(nullptr);

  int out_pipe[2];
  int err_pipe[2];
  if (::pipe2(out_pipe, O_CLOEXEC) != 0) return IoError("pipe: " + std::string(strerror(errno)));
  if (::pipe2(err_pipe, O_CLOEXEC) != 0) {
    ::close(out_pipe[0]);
    ::close(out_pipe[1]);
    return IoError("pipe: " + std::string(strerror(errno)));
  }
  const pid_t pid = ::fork();
  if (pid < 0) return IoError("fork: " + std::string(strerror(errno)));
  if (pid == 0) {
    const int null_fd = ::open("/dev/null", O_RDONLY);
    ::dup2(null_fd, STDIN_FILENO);
    ::dup2(out_pipe[1], STDOUT_FILENO);
    ::dup2(err_pipe[1], STDERR_FILENO);
    ::execve(argv[0], argv.data(), envp.data());
    _exit(127);
  }
  ::close(out_pipe[1]);
  ::close(err_pipe[1]);

  CommandResult result;
  const auto deadline = Clock::now() + timeout;
  bool open[2] = {true, true};
  const int fds[2] = {out_pipe[0], err_pipe[0]};
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
        (i == 0 ? result.out : result.err).append(buf, static_cast<std::size_t>(n));
      } else if (n == 0 || errno != EINTR) {
        open[i] = false;
      }
    }
  }
  ::close(fds[0]);
  ::close(fds[1]);
  int status = 0;
  for (;;) {
    const pid_t done = ::waitpid(pid, &status, WNOHANG);
    if (done == pid) break;
    if (Clock::now() >= deadline) {
      ::kill(pid, SIGKILL);
      ::waitpid(pid, &status, 0);
      return Timeout("brdfctl " + (args.empty() ? std::string() : args[0]) +
                     " did not finish within " + std::to_string(timeout.count()) +
                     " ms; it printed:\n" + result.out + result.err);
    }
    ::usleep(10000);
  }
  result.exit_code = ExitCode(status);
  return result;
}

std::vector<std::string> Lines(const std::string& text) {
  std::vector<std::string> lines;
  std::istringstream in(text);
  std::string line;
  while (std::getline(in, line)) lines.push_back(line);
  return lines;
}

}  // namespace brdf::testing
