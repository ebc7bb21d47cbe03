// SIMULATOR ONLY. `brdfctl sim-mount sample|white|dark|from-prompt --modbus HOST:PORT` does by
// remote what the operator does by hand on a real rig: it puts the sample, the white standard or
// the closed shutter in front of brdf-sim's meter, by writing register 0 of brdf-sim's control unit
// (tools/brdf-sim/stage/control_map.h) over Modbus TCP. A real rig has no such register; on one,
// this command fails to connect or writes nothing that matters — do not point it at real drives.
// `from-prompt` reads BRDF_PROMPT_KIND (set by `watch --on-prompt`, watch/prompt_hook.h) and mounts
// what the prompt asks for: mount_white → white, mount_sample → sample, close_shutter → dark;
// relocate_lamp_and_detector (the sample-fixed method) places lamp and detector by hand at the
// prompt's target (BRDF_PROMPT_THETA_I … _PHI_O; registers 29–33), which the optics then use
// instead of the holder's pose; relocate_detector (a sample-rotation rig) makes the optics follow
// the holder's pose again; the γ dial needs nothing.
#pragma once

#include <optional>
#include <ostream>
#include <string>
#include <vector>

#include "core/pose.h"
#include "core/status.h"
#include "tools/brdfctl/command.h"

namespace brdf::ctl {

// "sample" 0, "white" 1, "dark" 2 (the register's values); nullopt for anything else.
std::optional<int> MountedTargetValue(const std::string& target);

// The target a prompt kind needs ("white", "sample", "dark"), or "" when it needs none.
std::string TargetForPromptKind(const std::string& prompt_kind);

// Writes `values` from register `address` on control unit `unit` at `modbus` ("host:port").
Status WriteSimControl(const std::string& modbus, int unit, int address,
                       const std::vector<std::uint16_t>& values);

// Writes the mounted-target register of control unit `unit` at `modbus` ("host:port").
Status SimMount(const std::string& modbus, int unit, int value);

// The placed-by-hand registers 29–33 for `placed` (1, then signed centidegrees); kInvalidArgument
// naming the angle when one is outside θ 0–90°, φ −180–180°.
Result<std::vector<std::uint16_t>> PlacedRegisters(const Directions& placed);

// The prompt's target from BRDF_PROMPT_THETA_I … _PHI_O; kInvalidArgument naming a missing or
// unparsable variable.
Result<Directions> PlacedFromPromptEnvironment();

// The subcommand: resolves `target` (from-prompt through $BRDF_PROMPT_KIND), writes, reports.
int RunSimMount(std::ostream& out, std::ostream& err, const std::string& target,
                const std::string& modbus, int unit);

// `sim-mount`, with its flags (command.h), under the heading "Simulator only (brdf-sim)". It runs
// without brdfd: the shared flags (--address, --token-file, …) are ignored.
void RegisterSimMountCommand(CommandRegistry& registry);

}  // namespace brdf::ctl
