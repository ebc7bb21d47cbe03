#include "tests/support/sim/process.h"

#include <cstdlib>
#include <set>
#include <string>

namespace brdf::testing {
namespace {

using Clock = std::chrono::steady_clock;

std::string Join(const std::vector<std::string>& lines) {
  std::string out;
  for (const auto& l : lines) out += (out.empty() ? "" : " | ") + l;
  return out.empty() ? "(nothing)" : out;
}

}  // namespace

Result<std::string> BrdfSimBinary() {
  return BuiltProgram("brdf-sim", "tools/brdf-sim/brdf-sim", "BRDF_SIM_BINARY");
}

Result<std::unique_ptr<SimProcess>> SimProcess::Start(const std::vector<std::string>& args,
                                                      std::chrono::milliseconds timeout) {
  BRDF_ASSIGN_OR_RETURN(auto binary, BrdfSimBinary());

  std::unique_ptr<SimProcess> sim(new SimProcess());
  BRDF_ASSIGN_OR_RETURN(std::unique_ptr<ChildProcess> child,
                        ChildProcess::Launch("brdf-sim", binary, LaunchOptions(args)));
  sim->child_ = std::move(child);

  const auto deadline = Clock::now() + timeout;
  for (;;) {
    Result<std::string> read = sim->child_->ReadLine(deadline);
    if (read.status().code() == StatusCode::kTimeout) {
      return Timeout("brdf-sim did not print 'ready' within " + std::to_string(timeout.count()) +
                     " ms (printed: " + Join(sim->lines_) + "); see its log on stderr");
    }
    if (!read.ok()) {
      std::optional<int> code = sim->child_->WaitUntil(Clock::now() + std::chrono::seconds(2));
      return Internal("brdf-sim exited during start-up" +
                      (code ? " with code " + std::to_string(*code) : std::string()) +
                      " (printed: " + Join(sim->lines_) + "); see its log on stderr");
    }
    std::string line = std::move(*read);
    if (!line.empty() && line.back() == '\r') line.pop_back();
    sim->lines_.push_back(line);
    if (Status s = sim->ParseLine(line); !s.ok()) {
      return s.WithContext("brdf-sim start-up (printed so far: " + Join(sim->lines_) + ")");
    }
    if (line == "ready") return sim;
  }
}

Status SimProcess::ParseLine(const std::string& line) {
  const std::size_t space = line.find(' ');
  const std::string key = line.substr(0, space);
  const std::string value = space == std::string::npos ? "" : line.substr(space + 1);
  static const std::set<std::string> kMeters = {"pr650",  "pr655",   "pr670",
                                                "cs2000", "cs2000a", "cs3000"};
  if (kMeters.count(key) > 0 && !value.empty()) {
    pr650_path_ = value;
    meter_ = key;
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
      return ProtocolError(
          "'ready' came before the meter (pr650 …), modbus-tcp and control-unit lines");
    }
  } else {
    return ProtocolError("unexpected start-up line '" + line +
                         "' (the contract is in tools/brdf-sim/README.md)");
  }
  return Status::Ok();
}

Result<int> SimProcess::Stop(std::chrono::milliseconds timeout) {
  if (!child_ || !child_->running()) return Internal("brdf-sim was already stopped");
  std::optional<int> code = child_->Terminate(timeout);
  if (!code) {
    return Timeout("brdf-sim did not exit within " + std::to_string(timeout.count()) +
                   " ms of SIGTERM; killed it");
  }
  return *code;
}

SimProcess::~SimProcess() {
  if (child_ && child_->running()) (void)Stop();
}

Result<CommandResult> RunBrdfSim(const std::vector<std::string>& args,
                                 std::chrono::milliseconds timeout) {
  BRDF_ASSIGN_OR_RETURN(auto binary, BrdfSimBinary());
  return RunToCompletion("brdf-sim", binary, LaunchOptions(args), timeout);
}

}  // namespace brdf::testing
