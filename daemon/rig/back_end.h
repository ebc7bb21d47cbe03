// RigBackEnd: what brdfd serves, opened from its configuration: the SQLite store, shipping to the
// lab archive ([archive]; engine/shipper.h), the SessionManager over the rig (devices connect in
// the background), recovery of the sessions a dead daemon was driving (they come back paused),
// the index cache fed by each committed reading, and the API's views of them (catalogue.h,
// port.h).
#pragma once

#include <chrono>
#include <memory>

#include "core/status.h"
#include "daemon/api/server.h"
#include "daemon/config/config.h"
#include "daemon/engine/rig.h"
#include "daemon/engine/session_manager.h"
#include "daemon/engine/shipper.h"
#include "daemon/index/cache.h"
#include "daemon/rig/catalogue.h"
#include "daemon/rig/port.h"
#include "storage/session_store.h"

namespace brdf::daemon {

class RigBackEnd {
 public:
  // Opens it all over `rig` (Rig::FromConfig). A failure (the store, the archive's outbox, the
  // recovery) is logged and returned; nothing is left running.
  static Result<std::unique_ptr<RigBackEnd>> Open(const Config& config, std::unique_ptr<Rig> rig);
  // Stops shipping, then the manager (Shutdown(10 s) unless done before).
  ~RigBackEnd();
  RigBackEnd(const RigBackEnd&) = delete;
  RigBackEnd& operator=(const RigBackEnd&) = delete;

  // For the server: "brdfd", its sessions, its indexes, its rig.
  BackEnd Served();

  // At SIGTERM / SIGINT: a deferred pause of the running session (its step in progress gets up
  // to `timeout`, then is cancelled and redone on resume), the devices closed; the index cache
  // hears of no reading after it.
  void Shutdown(std::chrono::milliseconds timeout);

 private:
  RigBackEnd() = default;
  // Shipping ([archive]), or the outbox turned off.
  Status StartShipping(const Config& config);
  // The manager over `rig`, sessions recovered.
  Status StartManager(const Config& config, std::unique_ptr<Rig> rig);

  std::shared_ptr<storage::SessionStore> store_;
  std::unique_ptr<ArchiveShipper> shipper_;
  std::unique_ptr<SessionManager> manager_;
  std::unique_ptr<IndexCache> cache_;
  int cache_listener_ = 0;
  std::unique_ptr<RigCatalogue> catalogue_;
  std::unique_ptr<ManagerRigPort> port_;
};

}  // namespace brdf::daemon
