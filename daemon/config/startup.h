// The start-up steps brdfd and brdf-archive share: stop signals, logging, the configuration.
#pragma once

#include <signal.h>

#include <string>

#include "core/status.h"
#include "daemon/config/config.h"

namespace brdf::daemon {

// Blocks SIGTERM and SIGINT in the calling thread (call it before any thread starts: every thread
// inherits the mask, so only the main thread takes them, in sigwaitinfo / sigtimedwait) and
// ignores SIGPIPE (a client that hangs up must not kill the process). Returns the blocked set.
sigset_t BlockStopSignals();

// Makes a logger named `program` on stderr the default one, in the daemons' line format
// ("2026-12-04T20:23:06.663 info <message>").
void StartLogging(const std::string& program);

// Loads the TOML configuration at `path` and sets the log level to `log_level`, else the file's
// [log] level. A file that does not load: its status (the message names every bad key).
Result<Config> LoadConfigAndLogLevel(const std::string& path, const std::string& log_level);

}  // namespace brdf::daemon
