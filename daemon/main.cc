// brdfd: the spectral BRDF measurement daemon.
//
//   brdfd --config /etc/brdfd/brdfd.toml [--log-level L] [--shutdown-timeout S]
//
// Start-up: configuration (a bad file exits 2, naming every bad key and why), logging to stderr,
// one owner (a database, listen address or meter port another process holds exits 2, naming it),
// the rig from the configuration (exit 2 when it cannot be made), then the back end
// (rig/back_end.h: the SQLite store, recovery of sessions a dead daemon was driving, which come
// back paused, the rig's devices connecting in the background: an absent device shows as
// disconnected and is retried, the API is up meanwhile), then the gRPC server and, with [web]
// listen set, the web console (serve/serve.h). Once serving it prints "brdfd listening on
// <address>" (the real port when the configured port is 0), just after "brdfd web console on
// <url>" when there is one, and tells systemd READY=1 when built with libsystemd.
//
// SIGTERM / SIGINT: a deferred pause of the running session (the step in progress finishes, for
// up to --shutdown-timeout, then it is cancelled and redone on resume), the devices close, the
// server stops, exit 0. A second signal during that wait exits at once (exit 1); the database is
// crash-safe, so that loses nothing that was committed.
#include <signal.h>
#include <spdlog/spdlog.h>

#include <CLI/CLI.hpp>
#include <chrono>
#include <cstdio>
#include <memory>
#include <string>

#include "daemon/config/config.h"
#include "daemon/config/startup.h"
#include "daemon/engine/one_owner.h"
#include "daemon/engine/rig.h"
#include "daemon/rig/back_end.h"
#include "daemon/rpc/auth.h"
#include "daemon/serve/serve.h"
#include "drivers/exclusive_open.h"

namespace {

using namespace brdf;
using namespace brdf::daemon;

constexpr int kExitOk = 0;
constexpr int kExitFailure = 1;        // the store, the address or recovery failed
constexpr int kExitConfiguration = 2;  // a bad command line or configuration file, or
                                       // another process owns the database, address or meter

struct Flags {
  std::string config_path;
  std::string log_level;
  double shutdown_timeout_s = 60;
};

// The command line into `flags`; an exit code when the program must end now (help, or a bad
// command line), else -1.
int ParseFlags(int argc, char** argv, Flags* flags) {
  CLI::App app("brdfd: runs spectral BRDF measurement sessions on a rig and serves them over gRPC");
  app.add_option("--config", flags->config_path, "TOML configuration file")->required();
  app.add_option("--log-level", flags->log_level, "Overrides [log] level")
      ->check(CLI::IsMember({"trace", "debug", "info", "warn", "error", "critical", "off"}));
  app.add_option("--shutdown-timeout", flags->shutdown_timeout_s,
                 "Seconds a SIGTERM waits for the step in progress before cancelling it")
      ->check(CLI::Range(0.0, 3600.0));
  try {
    app.parse(argc, argv);
  } catch (const CLI::CallForHelp& e) {
    return app.exit(e);
  } catch (const CLI::ParseError& e) {
    app.exit(e);
    return kExitConfiguration;
  }
  return -1;
}

// One owner: refuses, before anything is touched, a database, address or meter port that another
// process holds (engine/one_owner.h). The database lock, in `*lock`, is held until exit.
Status ClaimOwnership(const Config& config, std::unique_ptr<DatabaseLock>* lock) {
  BRDF_ASSIGN_OR_RETURN(std::unique_ptr<DatabaseLock> acquired,
                        DatabaseLock::Acquire(config.storage.database));
  *lock = std::move(acquired);
  for (const Status& owned : {CheckListenAddressFree(config.server.listen),
                              drivers::CheckDeviceFree(config.meter.port)}) {
    if (!owned.ok()) return owned;
  }
  return Status::Ok();
}

void WarnAboutTokens(const Config& config, const Authenticator& auth) {
  if (auth.enabled()) {
    spdlog::info("{} bearer token(s) configured", auth.token_count());
  } else if (IsLoopbackAddress(config.server.listen)) {
    spdlog::warn("no [[auth.tokens]] configured: every local caller may control the rig");
  } else {
    spdlog::error(
        "no [[auth.tokens]] configured on the non-loopback address {}: ANYONE who "
        "can reach it may control the rig; add tokens",
        config.server.listen);
  }
}

int Refuse(const Status& status) {
  std::fprintf(stderr, "brdfd: %s\n", status.message().c_str());
  return kExitConfiguration;
}

// The back end on `config`, served until a stop signal.
int Run(const Config& config, const Flags& flags, const sigset_t& stop_signals) {
  Result<std::unique_ptr<Rig>> rig = Rig::FromConfig(config, Rig::Options());
  if (!rig.ok()) return Refuse(rig.status());
  Result<std::unique_ptr<RigBackEnd>> back_end = RigBackEnd::Open(config, std::move(*rig));
  if (!back_end.ok()) return kExitFailure;
  Authenticator auth(config.tokens);
  WarnAboutTokens(config, auth);
  const Program brdfd{"brdfd", "web console",
                      "pausing the running session (deferred), closing the devices, stopping",
                      "committed readings are safe; the session resumes from its first "
                      "unfinished step"};
  Result<std::unique_ptr<Serving>> serving =
      Serving::Start(brdfd, config, (*back_end)->Served(), auth);
  if (!serving.ok()) {
    // Taken since the check at start: still one owner per address.
    if (Status owned = CheckListenAddressFree(config.server.listen); !owned.ok()) {
      return Refuse(owned);
    }
    return kExitFailure;
  }
  const auto timeout =
      std::chrono::milliseconds(static_cast<long>(flags.shutdown_timeout_s * 1000));
  (*serving)->ServeUntilStopped(stop_signals, [&] { (*back_end)->Shutdown(timeout); });
  return kExitOk;
}

}  // namespace

int main(int argc, char** argv) {
  // Block the stop signals before any thread starts: every thread inherits the mask and only
  // the main thread takes them, in sigtimedwait. A client that hangs up must not kill us.
  const sigset_t stop_signals = BlockStopSignals();
  // A file-size limit (ulimit -f, a quota) must not kill us in the middle of a session: ignored,
  // a write past it fails with EFBIG, storage reports it and the session pauses.
  signal(SIGXFSZ, SIG_IGN);

  Flags flags;
  if (int code = ParseFlags(argc, argv, &flags); code >= 0) return code;
  StartLogging("brdfd");
  Result<Config> loaded = LoadConfigAndLogLevel(flags.config_path, flags.log_level);
  if (!loaded.ok()) return Refuse(loaded.status());
  const Config& config = *loaded;
  spdlog::info("brdfd starting: config {}, database {}, meter {}, stage {} {}", flags.config_path,
               config.storage.database, config.meter.port, config.stage.transport,
               config.stage.transport == "rtu"
                   ? config.stage.device
                   : config.stage.host + ":" + std::to_string(config.stage.port));
  std::unique_ptr<DatabaseLock> database_lock;
  if (Status owned = ClaimOwnership(config, &database_lock); !owned.ok()) return Refuse(owned);
  const int code = Run(config, flags, stop_signals);
  if (code == kExitOk) spdlog::info("stopped");
  return code;
}
