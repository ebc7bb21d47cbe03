// brdf-archive: the lab archive's read server (archive_server.h).
//
//   brdf-archive --config /etc/brdfd/archive.toml [--log-level L] [--migrate]
//
// The configuration is brdfd's format (config.h); brdf-archive reads [server] (listen, TLS,
// stream caps, interpolate threads), [[auth.tokens]], [log] and [archive] credentials: the file
// holding the archive's libpq conninfo, so that the password is neither on the command line nor
// in the configuration or the log; [web] listen and root. Other tables are ignored. With --migrate
// it first brings the archive's schema up to date (a role that may alter it), as a rig does when it
// connects.
//
// With [web] listen set it also serves the web explorer and a read-only console over the same
// services (web_gateway.h; TLS from [server.tls]) and prints "brdf-archive web explorer on
// <url>" first. Once serving it prints one line on stdout, "brdf-archive listening on <address>".
// SIGTERM / SIGINT: health NOT_SERVING, streams end, exit 0. Exit 2: a bad command line or
// configuration; 1: the archive cannot be read (unreachable, refused, wrong schema) or the address
// not bound.
#include <signal.h>
#include <spdlog/spdlog.h>

#include <CLI/CLI.hpp>
#include <cstdio>
#include <memory>
#include <string>

#include "daemon/api/server.h"
#include "daemon/archive/server.h"
#include "daemon/config/config.h"
#include "daemon/config/startup.h"
#include "daemon/gateway/http_server.h"
#include "daemon/rpc/auth.h"
#include "storage/archive/pg.h"
#include "storage/archive/reader.h"
#include "storage/archive/schema.h"

namespace {

constexpr int kExitOk = 0;
constexpr int kExitFailure = 1;
constexpr int kExitConfiguration = 2;

}  // namespace

int main(int argc, char** argv) {
  using namespace brdf;
  using namespace brdf::daemon;

  sigset_t stop_signals = BlockStopSignals();

  std::string config_path;
  std::string log_level;
  bool migrate = false;
  CLI::App app(
      "brdf-archive: serves the lab archive (PostgreSQL) with brdfd's read API: sessions of every "
      "rig, their readings, Interpolate, InterpolateBatch and RenderAppearance");
  app.add_option("--config", config_path,
                 "TOML configuration file (brdfd's format: [server], [[auth.tokens]], [log], "
                 "[archive] credentials)")
      ->required();
  app.add_option("--log-level", log_level, "Overrides [log] level")
      ->check(CLI::IsMember({"trace", "debug", "info", "warn", "error", "critical", "off"}));
  app.add_flag("--migrate", migrate,
               "Bring the archive's schema up to date before serving (needs a role that may "
               "alter it)");
  try {
    app.parse(argc, argv);
  } catch (const CLI::CallForHelp& e) {
    return app.exit(e);
  } catch (const CLI::ParseError& e) {
    app.exit(e);
    return kExitConfiguration;
  }

  StartLogging("brdf-archive");
  Result<Config> loaded = LoadConfigAndLogLevel(config_path, log_level);
  if (!loaded.ok()) {
    std::fprintf(stderr, "brdf-archive: %s\n", loaded.status().message().c_str());
    return kExitConfiguration;
  }
  const Config& config = *loaded;
  if (!config.archive.enabled()) {
    std::fprintf(stderr,
                 "brdf-archive: config %s: [archive] credentials is missing; give the path of a "
                 "file holding the archive's libpq conninfo\n",
                 config_path.c_str());
    return kExitConfiguration;
  }
  Result<std::string> conninfo = storage::ReadConninfoFile(config.archive.credentials);
  if (!conninfo.ok()) {
    std::fprintf(stderr, "brdf-archive: config archive.credentials: %s\n",
                 conninfo.status().message().c_str());
    return kExitConfiguration;
  }
  if (migrate) {
    Result<std::unique_ptr<storage::PgConnection>> conn = storage::PgConnection::Open(*conninfo);
    Status migrated =
        conn.ok() ? storage::MigrateArchive(**conn, storage::ArchiveMigrations()) : conn.status();
    if (!migrated.ok()) {
      spdlog::critical("migrating the archive: {}", migrated.ToString());
      return kExitFailure;
    }
  }
  Result<std::shared_ptr<storage::ArchiveReader>> archive = storage::ArchiveReader::Open(*conninfo);
  if (!archive.ok()) {
    spdlog::critical("{} (credentials from {})", archive.status().ToString(),
                     config.archive.credentials);
    return kExitFailure;
  }
  Authenticator auth(config.tokens);
  if (!auth.enabled()) {
    spdlog::warn(
        "no [[auth.tokens]] configured: anyone who can reach {} may read the whole archive",
        config.server.listen);
  }
  Result<std::unique_ptr<ArchiveServer>> server =
      ArchiveServer::Start(config.server, *archive, auth, ArchiveServer::Options());
  if (!server.ok()) {
    spdlog::critical("{}", server.status().ToString());
    return kExitFailure;
  }
  spdlog::info("serving the archive (credentials from {}) on {} ({})", config.archive.credentials,
               (*server)->address(), (*server)->tls() ? "TLS" : "plaintext");
  std::unique_ptr<WebGateway> web;
  if (!config.web.listen.empty()) {
    Result<std::unique_ptr<WebGateway>> started =
        WebGateway::Start(config.web, config.server.tls, DefaultWebRoot(config.web),
                          (*server)->InProcessChannel(), auth, "brdf-archive");
    if (!started.ok()) {
      spdlog::critical("{}", started.status().ToString());
      (*server)->Shutdown(std::chrono::seconds(1));
      return kExitFailure;
    }
    web = std::move(*started);
    std::printf("brdf-archive web explorer on %s\n", web->url().c_str());
  }
  std::printf("brdf-archive listening on %s\n", (*server)->address().c_str());
  std::fflush(stdout);

  int signal_number = 0;
  while (signal_number <= 0) signal_number = sigwaitinfo(&stop_signals, nullptr);
  spdlog::info("{}: stopping", signal_number == SIGINT ? "SIGINT" : "SIGTERM");
  if (web) web->Stop();
  (*server)->Shutdown(std::chrono::seconds(2));
  spdlog::info("stopped");
  return kExitOk;
}
