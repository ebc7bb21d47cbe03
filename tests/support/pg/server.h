// A real PostgreSQL server for tests, from Debian's package (postgresql-15: initdb and postgres in
// /usr/lib/postgresql/<version>/bin), in a temporary directory on a free TCP port with its unix
// socket in that directory. PostgreSQL refuses to run as root (CI runs as root): then initdb and
// postgres run as the unprivileged user `nobody`, in a directory it owns.
//
// The server needs a password (scram-sha-256) on every connection, so a wrong password is
// refused as on a real archive. fsync is off (the tests never crash the machine, only the
// server, and committed data is then in the operating system's cache); synchronous_commit stays
// on, so a commit the client saw survives the server being killed.
#pragma once

#include <sys/types.h>

#include <cstdint>
#include <memory>
#include <string>

#include "core/status.h"

namespace brdf::testing {

class PgServer {
 public:
  // The directory holding initdb and postgres; "" when PostgreSQL is not installed.
  static std::string BinDir();
  // Why archive tests cannot run ("" when they can): the message a skipped test prints.
  static std::string Unavailable();

  struct Options {
    // 0: the server's directory is on the machine's disk. Otherwise a tmpfs of this size is
    // mounted on it (needs CAP_SYS_ADMIN; FailedPrecondition without, which a test skips on),
    // so that FillDisk can make the server's disk full.
    std::uint64_t disk_bytes = 0;
  };

  // initdb + start, waiting until the server accepts connections.
  static Result<std::unique_ptr<PgServer>> Start();
  static Result<std::unique_ptr<PgServer>> Start(const Options& options);
  ~PgServer();  // stops the server and removes its directory
  PgServer(const PgServer&) = delete;
  PgServer& operator=(const PgServer&) = delete;

  // Fast shutdown (SIGINT: clients are disconnected, committed data kept), waiting for the exit.
  Status Stop();
  // SIGKILL, as a crash.
  Status Kill();
  // Starts again on the same data directory and port.
  Status Restart();
  bool running() const { return pid_ > 0; }

  int port() const { return port_; }
  const std::string& dir() const { return dir_; }
  // libpq conninfo over the unix socket / over TCP to 127.0.0.1.
  std::string conninfo() const;
  std::string tcp_conninfo() const;
  std::string conninfo_with_password(const std::string& password) const;
  // Writes `conninfo` to a credentials file `path` (mode 0600) and returns the path.
  static Result<std::string> WriteCredentials(const std::string& path, const std::string& conninfo);

  // Runs `sql` with psql (-At: unaligned, tuples only) and returns its output, trimmed.
  Result<std::string> Psql(const std::string& sql) const;
  // The server's log so far.
  std::string log() const;

  // A full disk on the server (Options.disk_bytes only): a ballast file takes every free byte
  // of the server's tmpfs, so the next write that needs space fails with ENOSPC, as on a real
  // archive whose disk filled up. FreeDisk removes the ballast.
  Status FillDisk();
  Status FreeDisk();

 private:
  PgServer() = default;
  Status Launch();
  Status WaitReady();

  std::string dir_;
  std::string bin_;
  std::string password_;
  int port_ = 0;
  pid_t pid_ = -1;
  uid_t uid_ = 0;  // the user the server runs as
  gid_t gid_ = 0;
  bool drop_privileges_ = false;
  bool tmpfs_ = false;  // dir_ is a tmpfs mounted by Start
};

}  // namespace brdf::testing
