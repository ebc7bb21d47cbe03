// The gRPC server of brdfd and brdf-archive alike: the Control, Data and Interpolation services
// over a program's back end (a SessionCatalogue, an IndexCache and, on a rig, a RigPort), the
// standard health service (grpc.health.v1.Health: "" and each brdf.v1 service SERVING while up)
// and server reflection (grpc.reflection.v1 and v1alpha, reflection.h), on the configured
// address, in plaintext or TLS ([server.tls]; client_ca → clients must present a certificate).
// Every call passes the token gate first (token_gate.h: the bearer token is checked from the
// metadata, before the request is read). Three sets of threads answer:
//  - the control plane (the operator's verbs, GetRigStatus, health Check): ControlLoop's threads
//    on gRPC's completion-queue API (control_loop.h), whatever the streams hold;
//  - Interpolate, the call analysis clients make by the thousand: the server's own loop threads on
//    the completion-queue API (interpolate_loop.h), one per two cores;
//  - the long-lived streams, WatchSession and StreamReadings: the stream pump's few threads on
//    gRPC's callback API (stream_pump.h, pumped_stream.h); a stream that waits holds no thread;
//  - everything else, the other streams among them: gRPC's synchronous pool, one thread per call
//    in flight, capped at ServerThreadCap (stream_registry.h), above the caps on open streams.
#pragma once

#include <grpcpp/server.h>

#include <chrono>
#include <memory>
#include <string>

#include "core/status.h"
#include "daemon/api/common.h"
#include "daemon/api/control.h"
#include "daemon/api/data.h"
#include "daemon/api/health.h"
#include "daemon/api/interpolate_loop.h"
#include "daemon/api/interpolation.h"
#include "daemon/api/reflection.h"
#include "daemon/api/rig_port.h"
#include "daemon/api/session_catalogue.h"
#include "daemon/api/stream_pump.h"
#include "daemon/config/config.h"
#include "daemon/index/cache.h"
#include "daemon/rpc/auth.h"
#include "daemon/rpc/control_loop.h"
#include "daemon/rpc/stream_registry.h"

namespace brdf::daemon {

// Interpolate's loop threads (interpolate_loop.h) on a machine with `cores` cores: one per two
// cores, at least one, at most 8. Each keeps a core busy under load; the others are left to
// gRPC's transport, the session and, on a shared machine, the clients.
int InterpolateLoopThreads(unsigned cores);

// True for addresses only this machine can reach: literal 127.0.0.0/8, ::1, ::ffff:127.x.y.z,
// "localhost", unix sockets. Host names (other than localhost) and 0.0.0.0 / [::] are not.
bool IsLoopbackAddress(const std::string& listen);

// What a program serves.
struct BackEnd {
  std::string program;                    // "brdfd", "brdf-archive": WhoAmI's server, messages
  SessionCatalogue* catalogue = nullptr;  // the sessions (required)
  IndexCache* cache = nullptr;            // Interpolation's indexes over them (required)
  RigPort* rig = nullptr;                 // the rig; null: none (its verbs are refused)
  ExportInterpolants::Options exports;    // the exports' kept interpolants ([export])
};

class Server {
 public:
  // Builds the services over `back_end` and starts serving on config.listen (port 0: any free
  // port; see address()). Errors: kConfigurationError when a TLS file cannot be read or holds no
  // PEM block of its kind, or interpolate_cpus names a CPU the process may not use; kIoError
  // when the address cannot be bound (in use, not allowed, no such interface) or gRPC refuses the
  // certificate/key pair. Logs a warning when a non-loopback address is served in plaintext or
  // the TLS key is readable by others, and logs the limits (common.h) it enforces. The back end's
  // parts and `auth` must outlive the server.
  static Result<std::unique_ptr<Server>> Start(const ServerConfig& config, const BackEnd& back_end,
                                               const Authenticator& auth);
  // Shutdown(1 s) if not called before.
  ~Server();
  Server(const Server&) = delete;
  Server& operator=(const Server&) = delete;

  // Where it listens, with the port actually bound ("127.0.0.1:43123", "unix:/run/brdfd.sock").
  const std::string& address() const { return address_; }
  int port() const { return port_; }
  bool tls() const { return tls_; }

  // A channel to these services inside the process (no socket, no TLS): calls on it pass the
  // same authentication, roles, validation and limits as calls from the network. The web
  // gateway (gateway/http_server.h) forwards the browser's calls through it.
  std::shared_ptr<grpc::Channel> InProcessChannel();

  // Health → NOT_SERVING, long-lived streams end (after sending what is queued), then calls in
  // flight get up to `grace` to finish before they are cancelled. Idempotent.
  void Shutdown(std::chrono::milliseconds grace);

 private:
  Server(const ServerConfig& config, const BackEnd& back_end, const Authenticator& auth);
  // Registers the services, builds and starts the gRPC server, then the loops.
  Status Listen(const ServerConfig& config,
                const std::shared_ptr<grpc::ServerCredentials>& credentials, bool tls,
                const Authenticator& auth);
  void LogLimits(const ServerConfig& config) const;

  StopSignal stopping_;
  StreamRegistry streams_;  // before the services, which hold slots in it
  ControlLoop control_loop_;
  StreamPump pump_;  // before the services whose streams it runs
  HealthService health_;
  ControlService control_;
  DataService data_;
  InterpolationService interpolation_;
  InterpolateLoop interpolate_loop_;  // after interpolation_, which it serves
  ReflectionV1Service reflection_v1_;
  ReflectionV1AlphaService reflection_v1alpha_;
  std::unique_ptr<grpc::Server> server_;
  std::string address_;
  int port_ = 0;
  bool tls_ = false;
  bool shut_down_ = false;
};

}  // namespace brdf::daemon
