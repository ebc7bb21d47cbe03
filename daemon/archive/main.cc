// brdf-archive: the lab archive's read server: brdfd's API (api/server.h) over the archive
// (catalogue.h), served with serve/serve.h.
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
// Interpolation is brdfd's own service and index cache over the archive's records, so answers are
// the rig's bit for bit; a thread hands readings newly shipped to the cached sessions
// (refresher.h). Stateless: nothing but caches lives here, so several brdf-archives (processes,
// machines) can serve one archive behind a load balancer.
//
// With [web] listen set it also serves the web explorer and a read-only console over the same
// services (gateway/http_server.h; TLS from [server.tls]) and prints "brdf-archive web explorer on
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
#include <utility>

#include "daemon/archive/back_end.h"
#include "daemon/config/config.h"
#include "daemon/config/startup.h"
#include "daemon/rpc/auth.h"
#include "daemon/serve/serve.h"
#include "storage/archive/pg.h"
#include "storage/archive/reader.h"
#include "storage/archive/schema.h"

namespace {

using namespace brdf;
using namespace brdf::daemon;

constexpr int kExitOk = 0;
constexpr int kExitFailure = 1;
constexpr int kExitConfiguration = 2;

struct Flags {
  std::string config_path;
  std::string log_level;
  bool migrate = false;
};

// The command line into `flags`; an exit code when the program must end now (help, or a bad
// command line), else -1.
int ParseFlags(int argc, char** argv, Flags* flags) {
  CLI::App app(
      "brdf-archive: serves the lab archive (PostgreSQL) with brdfd's read API: sessions of every "
      "rig, their readings, Interpolate, InterpolateBatch and RenderAppearance");
  app.add_option("--config", flags->config_path,
                 "TOML configuration file (brdfd's format: [server], [[auth.tokens]], [log], "
                 "[archive] credentials)")
      ->required();
  app.add_option("--log-level", flags->log_level, "Overrides [log] level")
      ->check(CLI::IsMember({"trace", "debug", "info", "warn", "error", "critical", "off"}));
  app.add_flag("--migrate", flags->migrate,
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
  return -1;
}

// The archive's conninfo from [archive] credentials; an exit code (2, said on stderr) when the
// configuration does not give a readable one, else -1.
int ReadConninfo(const Config& config, const std::string& config_path, std::string* conninfo) {
  if (!config.archive.enabled()) {
    std::fprintf(stderr,
                 "brdf-archive: config %s: [archive] credentials is missing; give the path of a "
                 "file holding the archive's libpq conninfo\n",
                 config_path.c_str());
    return kExitConfiguration;
  }
  Result<std::string> read = storage::ReadConninfoFile(config.archive.credentials);
  if (!read.ok()) {
    std::fprintf(stderr, "brdf-archive: config archive.credentials: %s\n",
                 read.status().message().c_str());
    return kExitConfiguration;
  }
  *conninfo = std::move(*read);
  return -1;
}

// The archive, its schema first brought up to date with `migrate`; failures logged.
Result<std::shared_ptr<storage::ArchiveReader>> OpenArchive(const Config& config,
                                                            const std::string& conninfo,
                                                            bool migrate) {
  if (migrate) {
    Result<std::unique_ptr<storage::PgConnection>> conn = storage::PgConnection::Open(conninfo);
    Status migrated =
        conn.ok() ? storage::MigrateArchive(**conn, storage::ArchiveMigrations()) : conn.status();
    if (!migrated.ok()) {
      spdlog::critical("migrating the archive: {}", migrated.ToString());
      return migrated;
    }
  }
  Result<std::shared_ptr<storage::ArchiveReader>> archive = storage::ArchiveReader::Open(conninfo);
  if (!archive.ok()) {
    spdlog::critical("{} (credentials from {})", archive.status().ToString(),
                     config.archive.credentials);
  }
  return archive;
}

// The archive served until a stop signal.
int Run(const Config& config, std::shared_ptr<storage::ArchiveReader> archive,
        const sigset_t& stop_signals) {
  ArchiveBackEnd back_end(std::move(archive), std::chrono::seconds(1),
                          IndexCacheOptionsFrom(config));
  Authenticator auth(config.tokens);
  if (!auth.enabled()) {
    spdlog::warn(
        "no [[auth.tokens]] configured: anyone who can reach {} may read the whole archive",
        config.server.listen);
  }
  spdlog::info("serving the archive (credentials from {})", config.archive.credentials);
  const Program program{"brdf-archive", "web explorer", "stopping",
                        "nothing is lost: the archive is only read here"};
  Result<std::unique_ptr<Serving>> serving =
      Serving::Start(program, config, back_end.Served(), auth);
  if (!serving.ok()) return kExitFailure;
  (*serving)->ServeUntilStopped(stop_signals, [&] { back_end.Stop(); });
  return kExitOk;
}

}  // namespace

int main(int argc, char** argv) {
  const sigset_t stop_signals = BlockStopSignals();
  Flags flags;
  if (int code = ParseFlags(argc, argv, &flags); code >= 0) return code;
  StartLogging("brdf-archive");
  Result<Config> loaded = LoadConfigAndLogLevel(flags.config_path, flags.log_level);
  if (!loaded.ok()) {
    std::fprintf(stderr, "brdf-archive: %s\n", loaded.status().message().c_str());
    return kExitConfiguration;
  }
  const Config& config = *loaded;
  std::string conninfo;
  if (int code = ReadConninfo(config, flags.config_path, &conninfo); code >= 0) return code;
  Result<std::shared_ptr<storage::ArchiveReader>> archive =
      OpenArchive(config, conninfo, flags.migrate);
  if (!archive.ok()) return kExitFailure;
  const int code = Run(config, std::move(*archive), stop_signals);
  if (code == kExitOk) spdlog::info("stopped");
  return code;
}
