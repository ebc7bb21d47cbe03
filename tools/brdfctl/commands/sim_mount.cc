#include "tools/brdfctl/commands/sim_mount.h"

#include <modbus.h>

#include <CLI/CLI.hpp>
#include <cerrno>
#include <cmath>
#include <cstdint>
#include <cstdlib>
#include <iostream>
#include <memory>
#include <vector>

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

namespace {
const char* const kPlacedNames[] = {"θi", "φi", "θo", "φo"};
}  // namespace

std::string TargetForPromptKind(const std::string& kind) {
  if (kind == "mount_white") return "white";
  if (kind == "mount_sample") return "sample";
  if (kind == "close_shutter") return "dark";
  return "";
}

Status WriteSimControl(const std::string& modbus, int unit, int address,
                       const std::vector<std::uint16_t>& values) {
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
  const int n = static_cast<int>(values.size());
  if (modbus_set_slave(ctx, unit) != 0 || modbus_connect(ctx) != 0) {
    result = Disconnected("cannot connect to brdf-sim's Modbus server at " + where + ": " +
                          modbus_strerror(errno) + "; is brdf-sim running on that port?");
  } else if (modbus_write_registers(ctx, address, n, values.data()) != n) {
    result = DeviceError(0, "writing register " + std::to_string(address) + " on " + where +
                                " failed: " + modbus_strerror(errno) +
                                "; is this brdf-sim's control unit (it printed control-unit N)?");
  }
  modbus_close(ctx);
  modbus_free(ctx);
  return result;
}

Status SimMount(const std::string& modbus, int unit, int value) {
  return WriteSimControl(modbus, unit, sim::control_map::kMountedTarget,
                         {static_cast<std::uint16_t>(value)});
}

Result<std::vector<std::uint16_t>> PlacedRegisters(const Directions& d) {
  const double values[] = {d.theta_i, d.phi_i, d.theta_o, d.phi_o};
  std::vector<std::uint16_t> regs = {1};  // placed by hand
  namespace cm = sim::control_map;
  for (int k = 0; k < 4; ++k) {
    const auto address = static_cast<std::uint16_t>(cm::kPlacedThetaI + k);
    const double v = values[k];
    if (!std::isfinite(v) || !cm::PlacedAngleInRange(address, v)) {
      return InvalidArgument(std::string("the placed direction ") + kPlacedNames[k] + " = " +
                             std::to_string(v) + "° is outside " +
                             (k % 2 == 0 ? "0–90°" : "−180–180°"));
    }
    regs.push_back(cm::ToCentidegrees(v));
  }
  return regs;
}

Result<Directions> PlacedFromPromptEnvironment() {
  const char* names[] = {"BRDF_PROMPT_THETA_I", "BRDF_PROMPT_PHI_I", "BRDF_PROMPT_THETA_O",
                         "BRDF_PROMPT_PHI_O"};
  double v[4];
  for (int k = 0; k < 4; ++k) {
    const char* text = std::getenv(names[k]);
    char* end = nullptr;
    v[k] = text == nullptr ? 0 : std::strtod(text, &end);
    if (text == nullptr || end == text || *end != '\0') {
      return InvalidArgument(std::string(names[k]) + " is " +
                             (text ? "\"" + std::string(text) + "\"" : "not set") +
                             ": a relocate_lamp_and_detector prompt carries its target directions "
                             "(run sim-mount from-prompt from `brdfctl watch --on-prompt`)");
    }
  }
  return Directions{v[0], v[1], v[2], v[3]};
}

namespace {

// relocate_lamp_and_detector: lamp and detector placed by hand where the prompt's target says.
int PlaceByHand(std::ostream& out, std::ostream& err, const std::string& modbus, int unit) {
  const Result<Directions> placed = PlacedFromPromptEnvironment();
  if (!placed.ok()) return ReportLocalError(err, placed.status());
  const Result<std::vector<std::uint16_t>> regs = PlacedRegisters(*placed);
  if (!regs.ok()) return ReportLocalError(err, regs.status());
  const Status status = WriteSimControl(modbus, unit, sim::control_map::kPlacedByHand, *regs);
  if (!status.ok()) return ReportLocalError(err, status);
  out << "sim-mount: lamp and detector placed by hand at θi " << placed->theta_i << "° φi "
      << placed->phi_i << "° θo " << placed->theta_o << "° φo " << placed->phi_o
      << "° on brdf-sim at " << modbus << "\n";
  return kExitOk;
}

}  // namespace

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
    if (std::string(kind) == "relocate_lamp_and_detector")
      return PlaceByHand(out, err, modbus, unit);
    if (std::string(kind) == "relocate_detector") {
      // A sample-rotation rig's prompt: the optics follow the holder's pose again.
      const Status status = WriteSimControl(modbus, unit, sim::control_map::kPlacedByHand, {0});
      if (!status.ok()) return ReportLocalError(err, status);
    }
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
