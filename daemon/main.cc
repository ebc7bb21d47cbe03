// brdfd: the spectral BRDF measurement daemon.
//
//   brdfd --config /etc/brdfd/brdfd.toml [--log-level L] [--shutdown-timeout S]
//
// Start-up: configuration (a bad file exits 2, naming every bad key and why), logging to stderr,
// one owner (a database, listen address or meter port another process holds exits 2, naming it),
// the SQLite store, recovery of sessions a dead daemon was driving (they come back paused), the
// rig (devices connect in the background: an absent device shows as disconnected and is
// retried, the API is up meanwhile), then the gRPC server. Once serving it prints exactly one
// line on stdout, "brdfd listening on <address>" (the real port when the configured port is 0),
// and tells systemd READY=1 when built with libsystemd. With [web] listen set, the web console
// (web_gateway.h) starts first and its line, "brdfd web console on <url>", comes just before.
//
// SIGTERM / SIGINT: a deferred pause of the running session (the step in progress finishes, for
// up to --shutdown-timeout, then it is cancelled and redone on resume), the devices close, the
// server stops, exit 0. A second signal during that wait exits at once (exit 1); the database is
// crash-safe, so that loses nothing that was committed.
#include <signal.h>
#include <spdlog/spdlog.h>

#include <CLI/CLI.hpp>
#include <atomic>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <ctime>
#include <memory>
#include <string>
#include <thread>

#include "daemon/api/server.h"
#include "daemon/config/config.h"
#include "daemon/config/startup.h"
#include "daemon/engine/one_owner.h"
#include "daemon/engine/rig.h"
#include "daemon/engine/session_manager.h"
#include "daemon/engine/shipper.h"
#include "daemon/gateway/http_server.h"
#include "daemon/index/cache.h"
#include "daemon/rig/catalogue.h"
#include "daemon/rig/port.h"
#include "daemon/rpc/auth.h"
#include "drivers/exclusive_open.h"
#include "storage/session_store.h"

#ifdef BRDF_HAVE_SYSTEMD
#include <systemd/sd-daemon.h>
#endif

namespace {

constexpr int kExitOk = 0;
constexpr int kExitFailure = 1;        // the store, the address or recovery failed
constexpr int kExitConfiguration = 2;  // a bad command line or configuration file, or
                                       // another process owns the database, address or meter

void Notify([[maybe_unused]] const std::string& state) {
#ifdef BRDF_HAVE_SYSTEMD
  sd_notify(0, state.c_str());
#endif
}

}  // namespace

int main(int argc, char** argv) {
  using namespace brdf;
  using namespace brdf::daemon;

  // Block the stop signals before any thread starts: every thread inherits the mask and only
  // the main thread takes them, in sigtimedwait. A client that hangs up must not kill us.
  sigset_t stop_signals = BlockStopSignals();
  // A file-size limit (ulimit -f, a quota) must not kill us in the middle of a session: ignored,
  // a write past it fails with EFBIG, storage reports it and the session pauses.
  signal(SIGXFSZ, SIG_IGN);

  std::string config_path;
  std::string log_level;
  double shutdown_timeout_s = 60;
  CLI::App app("brdfd: runs spectral BRDF measurement sessions on a rig and serves them over gRPC");
  app.add_option("--config", config_path, "TOML configuration file")->required();
  app.add_option("--log-level", log_level, "Overrides [log] level")
      ->check(CLI::IsMember({"trace", "debug", "info", "warn", "error", "critical", "off"}));
  app.add_option("--shutdown-timeout", shutdown_timeout_s,
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

  StartLogging("brdfd");
  Result<Config> loaded = LoadConfigAndLogLevel(config_path, log_level);
  if (!loaded.ok()) {
    std::fprintf(stderr, "brdfd: %s\n", loaded.status().message().c_str());
    return kExitConfiguration;
  }
  const Config& config = *loaded;
  spdlog::info("brdfd starting: config {}, database {}, meter {}, stage {} {}", config_path,
               config.storage.database, config.meter.port, config.stage.transport,
               config.stage.transport == "rtu"
                   ? config.stage.device
                   : config.stage.host + ":" + std::to_string(config.stage.port));

  // One owner: refuse, before touching anything, a database, address or meter port that another
  // process holds (daemon/engine/one_owner.h). The database lock is held until exit.
  Result<std::unique_ptr<DatabaseLock>> database_lock =
      DatabaseLock::Acquire(config.storage.database);
  if (!database_lock.ok()) {
    std::fprintf(stderr, "brdfd: %s\n", database_lock.status().message().c_str());
    return kExitConfiguration;
  }
  for (const Status& owned : {CheckListenAddressFree(config.server.listen),
                              drivers::CheckDeviceFree(config.meter.port)}) {
    if (!owned.ok()) {
      std::fprintf(stderr, "brdfd: %s\n", owned.message().c_str());
      return kExitConfiguration;
    }
  }

  Result<std::unique_ptr<storage::SessionStore>> opened =
      storage::SessionStore::Open(config.storage.database);
  if (!opened.ok()) {
    spdlog::critical("cannot open the database {}: {}", config.storage.database,
                     opened.status().ToString());
    return kExitFailure;
  }
  std::shared_ptr<storage::SessionStore> store = std::move(*opened);

  Result<std::unique_ptr<Rig>> rig = Rig::FromConfig(config, Rig::Options());
  if (!rig.ok()) {
    std::fprintf(stderr, "brdfd: %s\n", rig.status().message().c_str());
    return kExitConfiguration;
  }

  // Shipping to the lab archive: its own thread, never in the executor's way (archive_shipper.h).
  std::unique_ptr<ArchiveShipper> shipper;
  if (config.archive.enabled()) {
    ArchiveShipper::Options archive_options;
    archive_options.credentials_path = config.archive.credentials;
    archive_options.rig = RigName(config);
    archive_options.batch_readings = config.archive.batch_readings;
    archive_options.retry = std::chrono::milliseconds(config.archive.retry_ms);
    Result<std::unique_ptr<ArchiveShipper>> started =
        ArchiveShipper::Start(store, std::move(archive_options));
    if (!started.ok()) {
      spdlog::critical("cannot start shipping to the archive: {}", started.status().ToString());
      return kExitFailure;
    }
    shipper = std::move(*started);
    spdlog::info("shipping to the archive (credentials from {}) as rig \"{}\"",
                 config.archive.credentials, RigName(config));
  } else if (Status off = store->SetArchiveShipping(false); !off.ok()) {
    spdlog::critical("cannot turn off the archive outbox: {}", off.ToString());
    return kExitFailure;
  }

  SessionManager::Options manager_options;
  if (shipper != nullptr) {
    manager_options.archive_status = [&shipper] { return shipper->Snapshot(); };
  }
  manager_options.rig_description = ToRigDescription(config);
  manager_options.white_reflectance = config.sample.white_reflectance;
  manager_options.rig_name = RigName(config);
  if (Status adopted = store->AdoptUnnamedSessions(manager_options.rig_name); !adopted.ok()) {
    spdlog::critical("naming the rig of older sessions failed: {}", adopted.ToString());
    return kExitFailure;
  }
  SessionManager manager(store, std::shared_ptr<Rig>(std::move(*rig)), manager_options);

  Result<std::vector<SessionId>> recovered = manager.Recover();
  if (!recovered.ok()) {
    spdlog::critical("recovering interrupted sessions failed: {}", recovered.status().ToString());
    return kExitFailure;
  }
  if (!recovered->empty()) {
    spdlog::warn("{} session(s) were interrupted by the previous run and are now paused",
                 recovered->size());
  }

  IndexCache cache(store, IndexCache::Options(),
                   [&manager](SessionId session) { return manager.Plan(session); });
  const int cache_listener = manager.AddReadingListener(
      [&cache](SessionId session, const storage::ReadingRecord& reading) {
        cache.OnReading(session, reading);
      });

  Authenticator auth(config.tokens);
  if (!auth.enabled()) {
    if (IsLoopbackAddress(config.server.listen)) {
      spdlog::warn("no [[auth.tokens]] configured: every local caller may control the rig");
    } else {
      spdlog::error(
          "no [[auth.tokens]] configured on the non-loopback address {}: ANYONE who "
          "can reach it may control the rig; add tokens",
          config.server.listen);
    }
  } else {
    spdlog::info("{} bearer token(s) configured", auth.token_count());
  }

  RigCatalogue catalogue(manager);
  ManagerRigPort rig_port(manager);
  Result<std::unique_ptr<Server>> server =
      Server::Start(config.server, catalogue, rig_port, cache, auth);
  if (!server.ok()) {
    spdlog::critical("{}", server.status().ToString());
    manager.RemoveReadingListener(cache_listener);
    // Taken since the check above: still one owner per address.
    if (Status owned = CheckListenAddressFree(config.server.listen); !owned.ok()) {
      std::fprintf(stderr, "brdfd: %s\n", owned.message().c_str());
      return kExitConfiguration;
    }
    return kExitFailure;
  }
  spdlog::info("serving on {} ({})", (*server)->address(), (*server)->tls() ? "TLS" : "plaintext");
  std::unique_ptr<WebGateway> web;
  if (!config.web.listen.empty()) {
    Result<std::unique_ptr<WebGateway>> started =
        WebGateway::Start(config.web, config.server.tls, DefaultWebRoot(config.web),
                          (*server)->InProcessChannel(), auth);
    if (!started.ok()) {
      spdlog::critical("{}", started.status().ToString());
      (*server)->Shutdown(std::chrono::seconds(1));
      manager.RemoveReadingListener(cache_listener);
      return kExitFailure;
    }
    web = std::move(*started);
    std::printf("brdfd web console on %s\n", web->url().c_str());
  }
  std::printf("brdfd listening on %s\n", (*server)->address().c_str());
  std::fflush(stdout);
  Notify("READY=1\nSTATUS=serving on " + (*server)->address());

  // Wait for SIGTERM / SIGINT.
  int signal_number = 0;
  while (signal_number <= 0) signal_number = sigwaitinfo(&stop_signals, nullptr);
  spdlog::info("{}: pausing the running session (deferred), closing the devices, stopping",
               signal_number == SIGINT ? "SIGINT" : "SIGTERM");
  Notify("STOPPING=1");

  std::atomic<bool> done{false};
  std::thread stopper([&] {
    manager.Shutdown(std::chrono::milliseconds(static_cast<long>(shutdown_timeout_s * 1000)));
    manager.RemoveReadingListener(cache_listener);
    spdlog::info("sessions paused and devices closed; stopping the server");
    if (web) web->Stop();
    (*server)->Shutdown(std::chrono::seconds(2));
    done = true;
  });
  const timespec poll{0, 100 * 1000 * 1000};
  while (!done) {
    if (sigtimedwait(&stop_signals, nullptr, &poll) > 0) {
      spdlog::warn(
          "second stop signal: exiting now (committed readings are safe; the session "
          "resumes from its first unfinished step)");
      std::fflush(nullptr);
      std::_Exit(kExitFailure);
    }
  }
  stopper.join();
  if (shipper != nullptr) shipper->Stop();
  spdlog::info("stopped");
  return kExitOk;
}
