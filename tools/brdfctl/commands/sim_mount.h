// SIMULATOR ONLY. `brdfctl sim-mount sample|white|dark|from-prompt --modbus HOST:PORT` does by
// remote what the operator does by hand on a real rig: it puts the sample, the white standard or
// the closed shutter in front of brdf-sim's meter, by writing register 0 of brdf-sim's control unit
// (tools/brdf-sim/stage/control_map.h) over Modbus TCP. A real rig has no such register; on one,
// this command fails to connect or writes nothing that matters — do not point it at real drives.
// `from-prompt` reads BRDF_PROMPT_KIND (set by `watch --on-prompt`, watch/prompt_hook.h) and mounts
// what the prompt asks for: mount_white → white, mount_sample → sample, close_shutter → dark; other
// prompts (relocations, the γ dial) need nothing on the simulator, whose lamp and detector follow
// the stage.
#pragma once

#include <optional>
#include <ostream>
#include <string>

#include "core/status.h"
#include "tools/brdfctl/command.h"

namespace brdf::ctl {

// "sample" 0, "white" 1, "dark" 2 (the register's values); nullopt for anything else.
std::optional<int> MountedTargetValue(const std::string& target);

// The target a prompt kind needs ("white", "sample", "dark"), or "" when it needs none.
std::string TargetForPromptKind(const std::string& prompt_kind);

// Writes the mounted-target register of control unit `unit` at `modbus` ("host:port").
Status SimMount(const std::string& modbus, int unit, int value);

// The subcommand: resolves `target` (from-prompt through $BRDF_PROMPT_KIND), writes, reports.
int RunSimMount(std::ostream& out, std::ostream& err, const std::string& target,
                const std::string& modbus, int unit);

// `sim-mount`, with its flags (command.h), under the heading "Simulator only (brdf-sim)". It runs
// without brdfd: the shared flags (--address, --token-file, …) are ignored.
void RegisterSimMountCommand(CommandRegistry& registry);

}  // namespace brdf::ctl
