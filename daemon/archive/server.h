// ArchiveServer: brdf-archive's gRPC server -- the lab archive (PostgreSQL) served with the read
// side of brdfd's API, on the same terms as brdfd: the same token gate, roles and [server.tls]
// (MakeServerCredentials), the same limits and stream caps (stream_registry.h), the standard
// health service and server reflection.
//
//   Control        brdfd's own (api/control.h) over the archive's catalogue (catalogue.h):
//                  GetSession, ListSessions, ListSessionEvents; no rig, so its verbs are refused
//   Data           brdfd's own (api/data.h) over the archive's catalogue: StreamReadings,
//                  StreamReadingPoints (following a session polls the archive), Export
//   Interpolation  brdfd's own InterpolationService and InterpolateLoop over an IndexCache whose
//                  store is the archive (storage/archive/reader.h): the same code, over the same
//                  records, answers as on the rig, bit for bit
//
// brdf-archive's [web] listen puts the web gateway (web_gateway.h) in front of InProcessChannel():
// the browser explorer and a read-only console over these same services.
//
// Stateless: nothing but caches lives here, so several ArchiveServers (processes, machines) can
// serve one archive behind a load balancer. The index cache is kept current without commit
// events: every `refresh` a thread asks the archive for readings above those each cached session
// holds and hands them over (IndexCache::OnReading), so a session still recording on its rig
// grows here as it is shipped.
#pragma once

#include <grpcpp/channel.h>
#include <grpcpp/server.h>

#include <chrono>
#include <memory>
#include <string>
#include <thread>

#include "core/status.h"
#include "daemon/api/control.h"
#include "daemon/api/data.h"
#include "daemon/api/health.h"
#include "daemon/api/interpolate_loop.h"
#include "daemon/api/interpolation.h"
#include "daemon/api/reflection.h"
#include "daemon/archive/catalogue.h"
#include "daemon/config/config.h"
#include "daemon/index/cache.h"
#include "daemon/rpc/auth.h"
#include "daemon/rpc/control_loop.h"
#include "daemon/rpc/stream_registry.h"
#include "storage/archive/reader.h"

namespace brdf::daemon {

class ArchiveServer {
 public:
  struct Options {
    // How often cached sessions are brought up to date with the archive.
    std::chrono::milliseconds refresh{1000};
    IndexCache::Options cache;
  };

  // Serves `archive` on config.listen (port 0: any free port). Errors as Server::Start's.
  // `auth` must outlive the server.
  static Result<std::unique_ptr<ArchiveServer>> Start(
      const ServerConfig& config, std::shared_ptr<storage::ArchiveReader> archive,
      const Authenticator& auth, Options options);
  ~ArchiveServer();  // Shutdown(1 s)
  ArchiveServer(const ArchiveServer&) = delete;
  ArchiveServer& operator=(const ArchiveServer&) = delete;

  const std::string& address() const { return address_; }
  bool tls() const { return tls_; }
  IndexCache::Stats cache_stats() const { return cache_.stats(); }

  // A channel to this server inside the process: calls through it get the same authentication,
  // roles, validation and limits as calls from the network (the web gateway forwards the
  // browser's calls through it, as brdfd's does).
  std::shared_ptr<grpc::Channel> InProcessChannel();

  // Health → NOT_SERVING, streams end, calls in flight get `grace`. Idempotent.
  void Shutdown(std::chrono::milliseconds grace);

 private:
  ArchiveServer(const ServerConfig& config, std::shared_ptr<storage::ArchiveReader> archive,
                const Authenticator& auth, Options options);
  // The refresh thread's loop, until stopping_.
  void Refresh();

  std::shared_ptr<storage::ArchiveReader> archive_;
  Options options_;
  IndexCache cache_;
  StopSignal stopping_;
  StreamRegistry streams_;
  ControlLoop control_loop_;  // the health service's Check
  HealthService health_;
  ArchiveCatalogue catalogue_;
  ControlService control_;
  DataService data_;
  InterpolationService interpolation_;
  InterpolateLoop interpolate_loop_;
  ReflectionV1Service reflection_v1_;
  ReflectionV1AlphaService reflection_v1alpha_;
  std::unique_ptr<grpc::Server> server_;
  std::thread refresher_;
  std::string address_;
  bool tls_ = false;
  bool shut_down_ = false;
};

}  // namespace brdf::daemon
