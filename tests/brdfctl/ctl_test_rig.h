// What the brdfctl tests stand on: brdf-sim and brdfd as real processes (brdfd through
// tests/support/daemon/process.h), a generated configuration with an operator and an analyst
// token, and the environment a user of brdfctl would set (BRDF_ADDRESS, BRDF_TOKEN).
#pragma once

#include <memory>
#include <string>

#include "core/status.h"
#include "tests/brdfctl/ctl_runner.h"
#include "tests/support/daemon/process.h"
#include "tests/support/sim/modbus_control.h"
#include "tests/support/sim/process.h"
#include "tests/support/test_env.h"

namespace brdf::testing {

inline constexpr const char* kCtlOperatorToken = "ctl-operator-7d41c9e2b05a";
inline constexpr const char* kCtlAnalystToken = "ctl-analyst-3fa8e61c2d97";

class CtlRig {
 public:
  CtlRig();
  ~CtlRig();
  CtlRig(const CtlRig&) = delete;
  CtlRig& operator=(const CtlRig&) = delete;

  // Starts brdf-sim (50× time, no pacing, no wake window) and brdfd on a free port; waits until
  // brdfctl sees both devices connected.
  Status Start();

  const std::string& address() const { return daemon_->address(); }
  // "host:port" of brdf-sim's Modbus TCP server (for sim-mount).
  std::string modbus() const;
  ModbusControl& sim_control() { return *sim_control_; }
  const TempDir& dir() const { return dir_; }
  // The daemon's log so far (for failure messages).
  std::string log() const;

  // BRDF_ADDRESS and BRDF_TOKEN (the operator's, unless `token` is given).
  EnvVars Env(const std::string& token = kCtlOperatorToken) const;
  // Runs brdfctl against this daemon with Env(token).
  Result<CommandResult> Ctl(const std::vector<std::string>& args,
                            const std::string& token = kCtlOperatorToken,
                            std::chrono::milliseconds timeout = std::chrono::seconds(30)) const;

 private:
  TempDir dir_;
  std::unique_ptr<SimProcess> sim_;
  std::unique_ptr<ModbusControl> sim_control_;
  std::unique_ptr<DaemonProcess> daemon_;
};

}  // namespace brdf::testing
