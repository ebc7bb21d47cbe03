#include "tests/support/daemon/process.h"

#include <fstream>
#include <optional>
#include <sstream>

namespace brdf::testing {
namespace {

using Clock = std::chrono::steady_clock;
constexpr std::string_view kListening = "brdfd listening on ";

// stdout to a pipe (the "listening" line), stderr appended to `log_path`.
LaunchOptions DaemonLaunch(const std::vector<std::string>& args, const std::string& log_path) {
  LaunchOptions options;
  options.args = args;
  options.stderr_to = LaunchOptions::Stderr::kAppendToFile;
  options.stderr_path = log_path;
  return options;
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
  return BuiltProgram("brdfd", "daemon/brdfd", "BRDFD_BINARY");
}

Result<std::unique_ptr<DaemonProcess>> DaemonProcess::Start(const std::vector<std::string>& args,
                                                            const std::string& log_path,
                                                            std::chrono::milliseconds timeout) {
  BRDF_ASSIGN_OR_RETURN(std::string binary, BrdfdBinary());
  std::unique_ptr<DaemonProcess> d(new DaemonProcess());
  d->log_path_ = log_path;
  BRDF_ASSIGN_OR_RETURN(std::unique_ptr<ChildProcess> child,
                        ChildProcess::Launch("brdfd", binary, DaemonLaunch(args, log_path)));
  d->child_ = std::move(child);

  Result<std::string> line = d->child_->ReadLine(Clock::now() + timeout);
  if (line.status().code() == StatusCode::kTimeout) {
    return Timeout("brdfd did not print \"brdfd listening on …\" within " +
                   std::to_string(timeout.count()) + " ms; log:\n" + d->log());
  }
  if (!line.ok()) {
    std::optional<int> code = d->child_->WaitUntil(Clock::now() + std::chrono::seconds(2));
    return Internal("brdfd exited during start-up" +
                    (code ? " with code " + std::to_string(*code) : std::string()) + "; log:\n" +
                    d->log());
  }
  if (line->rfind(kListening, 0) != 0) {
    return ProtocolError("brdfd printed an unexpected line \"" + *line + "\"; log:\n" + d->log());
  }
  d->address_ = line->substr(kListening.size());
  return d;
}

DaemonProcess::~DaemonProcess() {
  Kill();
}

Result<int> DaemonProcess::Stop(std::chrono::milliseconds timeout) {
  if (!child_ || !child_->running()) return Internal("brdfd was already stopped");
  std::optional<int> code = child_->Terminate(timeout);
  if (!code) {
    return Timeout("brdfd did not exit within " + std::to_string(timeout.count()) +
                   " ms of SIGTERM; killed it. Log:\n" + log());
  }
  return *code;
}

void DaemonProcess::Kill() {
  if (child_) child_->Kill();
}

std::string DaemonProcess::log(std::size_t max_bytes) const {
  return Tail(log_path_, max_bytes);
}

Result<DaemonRun> RunBrdfd(const std::vector<std::string>& args, const std::string& log_path,
                           std::chrono::milliseconds timeout) {
  BRDF_ASSIGN_OR_RETURN(std::string binary, BrdfdBinary());
  Result<CommandResult> run =
      RunToCompletion("brdfd", binary, DaemonLaunch(args, log_path), timeout);
  if (!run.ok()) {
    if (run.status().code() == StatusCode::kTimeout) {
      return Timeout("brdfd did not exit within " + std::to_string(timeout.count()) + " ms");
    }
    return run.status();
  }
  return DaemonRun{run->exit_code, Tail(log_path, 100000)};
}

long ResidentKb(pid_t pid) {
  std::ifstream in("/proc/" + std::to_string(pid) + "/status");
  std::string line;
  while (std::getline(in, line)) {
    if (line.rfind("VmRSS:", 0) == 0) return std::stol(line.substr(6));
  }
  return -1;
}

}  // namespace brdf::testing
