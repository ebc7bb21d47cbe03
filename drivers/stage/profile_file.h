// Stage register profiles as files: a TOML table per profile (deploy/stage-profiles/*.toml, the
// format is documented in az.toml and docs/stage-modbus.md) holding the register addresses, word
// order, status bits, speed scale, ramp values with their unit, the block constants (operating
// current, operation data number), the trigger and the commands.
//
// The built-in profiles (`az`, `leadshine`, `moons`) are those same files, compiled into the
// binary at build time (builtin_profiles.h) and installed to share/brdfd/stage-profiles/ for a lab
// to copy; `[stage] profile_file` points brdfd at the lab's own.
//
// Every error is kConfigurationError naming the file, and for each bad key its line and what is
// wrong (every one of them, a line each), then what to do (core/toml/table_reader.h):
//   stage profile file /etc/brdfd/x.toml: line 40, column 10: status_bits.moving: must be an
//     integer, not a string
//   stage profile file /etc/brdfd/x.toml: fix the file (the shipped profiles in …)
// A parsed profile has passed ValidateProfile.
#pragma once

#include <string>
#include <string_view>
#include <vector>

#include "core/status.h"
#include "drivers/stage/register_profile.h"

namespace brdf::drivers::stage {

// Parses a profile from `text`; `source` names it in messages (a path, or "built-in 'az'").
Result<RegisterProfile> ParseProfileText(std::string_view text, const std::string& source);

// Reads and parses the file at `path` (kConfigurationError when it cannot be read).
Result<RegisterProfile> LoadProfileFile(const std::string& path);

// The built-in profile names, in the order shipped: az, leadshine, moons.
std::vector<std::string> BuiltinProfileNames();
// The text of a built-in profile file, empty for an unknown name.
std::string_view BuiltinProfileText(std::string_view name);
// A built-in profile; kConfigurationError naming the known ones for an unknown name.
Result<RegisterProfile> BuiltinProfile(std::string_view name);
// For the RegisterProfile factories: aborts with the message if a built-in file does not parse.
RegisterProfile BuiltinProfileOrDie(std::string_view name);

}  // namespace brdf::drivers::stage
