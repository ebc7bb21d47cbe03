// `brdfctl appearance <id> [--illuminant D65|A] [--method M] [--size N] [-o sphere.ppm]`: the
// sample's colour (CIE 45°:0°: XYZ, xy, sRGB hex) under D65 and illuminant A (or the one asked),
// and a sphere lit by a distant light, from the session's BRDF (Interpolation.RenderAppearance).
// -o writes the first illuminant's sphere as a binary PPM (P6; outside the disc white), or
// several files when both illuminants are asked: sphere-D65.ppm and sphere-A.ppm for -o
// sphere.ppm. --json: the AppearanceResponse on one line.
#pragma once

#include <string>

#include "tools/brdfctl/command.h"
#include "tools/brdfctl/command_context.h"

namespace brdf::ctl {

struct AppearanceOptions {
  std::string session_id;
  std::string illuminant;         // "D65", "A", or empty for both
  std::string method = "octant";  // octant, delaunay, nearest
  unsigned size = 0;              // 0: the daemon's default (128)
  std::string output;             // PPM file, or empty
};

int RunAppearance(CommandContext& ctx, const AppearanceOptions& options);

// `appearance`, with its flags (command.h).
void RegisterAppearanceCommand(CommandRegistry& registry);

}  // namespace brdf::ctl
