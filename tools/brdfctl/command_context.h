// What every subcommand runs with: the client, the output mode and where to write. Commands
// return the exit status of exit_codes.h; nothing throws.
#pragma once

#include <ostream>

#include "tools/brdfctl/client.h"

namespace brdf::ctl {

struct CommandContext {
  Client& client;
  bool json = false;  // --json: protobuf JSON of each reply, one object per line
  std::ostream& out;  // results
  std::ostream& err;  // errors, hints, and with --json also the human notes
};

}  // namespace brdf::ctl
