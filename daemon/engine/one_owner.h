// One daemon owns a rig: its database, its listen address and its meter's serial port. brdfd
// checks all three at start-up, before it touches anything, and refuses to start (exit 2) when
// another process holds one, naming that process and what to do.
//
//  - The database: an exclusive fcntl lock on "<database>.lock", held for the daemon's life (the
//    kernel drops it when the process dies, kill -9 included, so a crashed daemon never leaves a
//    stale lock). The file holds the owner's pid for people; the lock, not the file, decides.
//  - The listen address: bound without SO_REUSEPORT (server.cc), so a second daemon cannot share
//    the port; CheckListenAddressFree finds the listening process in /proc/net/tcp{,6}.
//  - The meter's port: drivers/exclusive_open.h (flock + TIOCEXCL while connected).
#pragma once

#include <memory>
#include <string>

#include "core/status.h"

namespace brdf::daemon {

class DatabaseLock {
 public:
  // Locks `database` for this process. kFailedPrecondition naming the holder ("database D is in
  // use by pid N (brdfd --config C)") when another process holds it; kIoError when the lock file
  // cannot be created (its directory is not writable, say).
  static Result<std::unique_ptr<DatabaseLock>> Acquire(const std::string& database);
  ~DatabaseLock();  // releases the lock (the file stays: removing it would race a new owner)
  DatabaseLock(const DatabaseLock&) = delete;
  DatabaseLock& operator=(const DatabaseLock&) = delete;

  const std::string& path() const { return path_; }  // "<database>.lock"

 private:
  DatabaseLock(int fd, std::string path) : fd_(fd), path_(std::move(path)) {}
  int fd_;
  std::string path_;
};

// Ok when nothing listens on `listen` ("host:port"; port 0, unix: addresses and unresolvable
// hosts are left to the server). kFailedPrecondition naming the listening process when the
// address is in use.
Status CheckListenAddressFree(const std::string& listen);

}  // namespace brdf::daemon
