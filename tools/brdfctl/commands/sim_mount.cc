#include "tools/brdfctl/commands/sim_mount.h"

#include <modbus.h>

#include <CLI/CLI.hpp>
#include <cerrno>
#include <cstdlib>
#include <iostream>
#include <memory>

#include "tools/brdf-sim/stage/control_map.h"
#include "tools/brdfctl/exit_codes.h"
#include "tools/brdfctl/rpc_error.h"

namespace brdf::ctl {

std::optional<int> MountedTargetValue(const std::string& target) {
  if (target == "sample") return 0;
  if (target == "white") return 1;
  if (target == "dark") return 2;
  return std::nullopt;
}

std::string TargetForPromptKind(const std::string& kind) {
  if (kind == "mount_white") return "white";
  if (kind == "mount_sample") return "sample";
  if (kind == "close_shutter") return "dark";
  return "";
}

Status SimMount(const std::string& modbus, int unit, int value) {
  const std::size_t colon = modbus.rfind(':');
  if (colon == std::string::npos || colon == 0 || colon + 1 == modbus.size() ||
      modbus.find_first_not_of("0123456789", colon + 1) != std::string::npos) {
    return InvalidArgument("--modbus \"" + modbus +
                           "\" is not host:port; give the address brdf-sim printed as "
                           "\"modbus-tcp <host>:<port>\"");
  }
  const std::string host = modbus.substr(0, colon);
  const int port = std::atoi(modbus.c_str() + colon + 1);
  const std::string where = modbus + " unit " + std::to_string(unit);
  modbus_t* ctx = modbus_new_tcp(host.c_str(), port);
  if (ctx == nullptr) {
    return InvalidArgument("cannot create a Modbus TCP context for " + where + ": " +
                           modbus_strerror(errno));
  }
  modbus_set_response_timeout(ctx, 2, 0);
  Status result = Status::Ok();
  if (modbus_set_slave(ctx, unit) != 0 || modbus_connect(ctx) != 0) {
    result = Disconnected("cannot connect to brdf-sim's Modbus server at " + where + ": " +
                          modbus_strerror(errno) + "; is brdf-sim running on that port?");
  } else if (modbus_write_register(ctx, sim::control_map::kMountedTarget,
                                   static_cast<std::uint16_t>(value)) != 1) {
    result = DeviceError(0, "writing the mounted target on " + where +
                                " failed: " + modbus_strerror(errno) +
                                "; is this brdf-sim's control unit (it printed control-unit N)?");
  }
  modbus_close(ctx);
  modbus_free(ctx);
  return result;
}

int RunSimMount(std::ostream& out, std::ostream& err, const std::string& target,
                const std::string& modbus, int unit) {
  std::string resolved = target;
  if (target == "from-prompt") {
    const char* kind = std::getenv("BRDF_PROMPT_KIND");
    if (kind == nullptr || *kind == '\0') {
      err << "brdfctl: sim-mount from-prompt needs BRDF_PROMPT_KIND (run it from "
             "`brdfctl watch --on-prompt`)\n";
      return kExitInvalid;
    }
    resolved = TargetForPromptKind(kind);
    if (resolved.empty()) {
      out << "sim-mount: prompt " << kind << " needs nothing mounted on the simulator\n";
      return kExitOk;
    }
  }
  const std::optional<int> value = MountedTargetValue(resolved);
  if (!value) {
    err << "brdfctl: sim-mount " << target << ": use sample, white, dark or from-prompt\n";
    return kExitInvalid;
  }
  const Status status = SimMount(modbus, unit, *value);
  if (!status.ok()) return ReportLocalError(err, status);
  out << "sim-mount: " << resolved << " mounted on brdf-sim at " << modbus << "\n";
  return kExitOk;
}

namespace {

Runner AddSimMountOptions(CLI::App& cmd) {
  struct Args {
    std::string target;
    std::string modbus;
    int unit = 100;
  };
  auto args = std::make_shared<Args>();
  cmd.add_option("target", args->target, "sample, white, dark or from-prompt")->required();
  cmd.add_option("--modbus", args->modbus, "brdf-sim's Modbus TCP host:port")
      ->envname("BRDF_SIM_MODBUS")
      ->required();
  cmd.add_option("--unit", args->unit, "brdf-sim's control unit id")->capture_default_str();
  // No daemon: sim-mount writes to brdf-sim directly.
  return [args](const GlobalOptions&) {
    return RunSimMount(std::cout, std::cerr, args->target, args->modbus, args->unit);
  };
}

}  // namespace

void RegisterSimMountCommand(CommandRegistry& registry) {
  registry.Add({"sim-mount",
                "SIMULATOR ONLY: mount sample, white or dark on brdf-sim (from-prompt: what "
                "$BRDF_PROMPT_KIND asks)",
                "Simulator only (brdf-sim)", AddSimMountOptions});
}

}  // namespace brdf::ctl
