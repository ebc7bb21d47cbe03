// `brdfctl readings <id>`: a session's readings (Data.StreamReadings) in id order, one line each
// (id, step, kind, pose, directions, quality, integration, label, and for samples their BRDF's
// expanded uncertainty ± k·u, --k), or one JSON object per reading with --json (with the spectrum
// and the uncertainty budget). --follow keeps the stream open until the session ends.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include "tools/brdfctl/command.h"
#include "tools/brdfctl/command_context.h"

namespace brdf::ctl {

struct ReadingsOptions {
  std::string session_id;
  bool follow = false;
  std::vector<std::string> kinds;  // "sample", "reference", "dark"; empty: all
  std::int64_t after_id = 0;
  bool spectra = false;  // readable output: also print each spectrum
  double k = 2;          // coverage factor of the ± columns (output/uncertainty_text.h)
};

int RunReadings(CommandContext& ctx, const ReadingsOptions& options);

// `readings`, with its flags (command.h).
void RegisterReadingsCommand(CommandRegistry& registry);

}  // namespace brdf::ctl
