// The gRPC server: the Control, Data and Interpolation services, the standard health service
// (grpc.health.v1.Health: "" and each brdf.v1 service SERVING while up) and server reflection
// (grpc.reflection.v1 and v1alpha, reflection_service.h),
// on the configured address, in plaintext or TLS ([server.tls]; client_ca → clients must present
// a certificate). Every call passes the token gate first (token_gate.h: the bearer token is
// checked from the metadata, before the request is read). Three sets of threads answer:
//  - the control plane (the operator's verbs, GetRigStatus, health Check): ControlLoop's threads
//    on gRPC's completion-queue API (control_loop.h), whatever the streams hold;
//  - Interpolate, the call analysis clients make by the thousand: brdfd's own loop threads on the
//    completion-queue API (interpolate_loop.h), one per two cores;
//  - everything else, the streams among them: gRPC's synchronous pool, one thread per call in
//    flight, capped at ServerThreadCap (stream_registry.h), above the caps on open streams.
#pragma once

#include <grpcpp/security/server_credentials.h>
#include <grpcpp/server.h>
#include <grpcpp/server_builder.h>

#include <chrono>
#include <initializer_list>
#include <memory>
#include <string>
#include <vector>

#include "core/status.h"
#include "daemon/api/common.h"
#include "daemon/api/control.h"
#include "daemon/api/data.h"
#include "daemon/api/health.h"
#include "daemon/api/interpolate_loop.h"
#include "daemon/api/interpolation.h"
#include "daemon/api/reflection.h"
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

// The brdf.v1 services by their full names (the health service's per-service status), and with
// them every service the server registers (reflection's list_services). brdf-archive serves the
// same.
std::vector<std::string> BrdfServiceNames();
std::vector<std::string> ServedServices();

// The server's credentials from [server] and [server.tls]: TLS (client certificates required
// when client_ca is set; `tls` true) or plaintext that still takes the token gate (a warning is
// logged when a non-loopback address is served in plaintext). kConfigurationError naming the key
// when a TLS file cannot be read or holds no PEM block of its kind. brdfd and brdf-archive both.
Result<std::shared_ptr<grpc::ServerCredentials>> MakeServerCredentials(const ServerConfig& config,
                                                                       bool* tls);

// What brdfd and brdf-archive set up alike on their builder: the listening port with
// `credentials` behind the token gate (token_gate.h), no SO_REUSEPORT (one server per address),
// the request size limit and the thread cap (ServerThreadCap). `*selected_port` is the port bound,
// once the server is built.
void PrepareServerBuilder(grpc::ServerBuilder& builder, const ServerConfig& config,
                          const std::shared_ptr<grpc::ServerCredentials>& credentials,
                          const Authenticator& auth, int* selected_port);
// After BuildAndStart (`built`: it returned a server): the address served, with the port bound
// ("127.0.0.1:43123", "unix:/run/brdfd.sock"); kIoError naming the address when nothing was bound.
Result<std::string> BoundAddress(const ServerConfig& config, bool built, int selected_port,
                                 bool tls);

// Everything else brdfd and brdf-archive do alike to serve: prepares a builder
// (PrepareServerBuilder), registers `services`, adds the completion queues of their Interpolate
// and control-plane loops, builds and starts the server into `*server` (null when gRPC could not
// build it), then, once the address is bound, starts both loops. Returns the address served
// (BoundAddress) and sets `*selected_port`. The loops' handlers (ServeOn) must be set first.
Result<std::string> BuildAndStartServer(const ServerConfig& config,
                                        const std::shared_ptr<grpc::ServerCredentials>& credentials,
                                        bool tls, const Authenticator& auth,
                                        std::initializer_list<grpc::Service*> services,
                                        InterpolateLoop& interpolate_loop,
                                        ControlLoop& control_loop,
                                        std::unique_ptr<grpc::Server>* server, int* selected_port);

class Server {
 public:
  // Builds the services and starts serving on config.listen (port 0: any free port; see
  // address()). Errors: kConfigurationError when a TLS file cannot be read or holds no PEM block
  // of its kind, kIoError when the address cannot be bound (in use, not allowed, no such
  // interface) or gRPC refuses the certificate/key pair. Logs a warning when a non-loopback
  // address is served in plaintext or the TLS key is readable by others, and logs the limits
  // (service_common.h) it enforces. `manager`, `cache` and `auth` must outlive it.
  static Result<std::unique_ptr<Server>> Start(const ServerConfig& config,
                                               SessionCatalogue& catalogue, RigPort& rig,
                                               IndexCache& cache, const Authenticator& auth);
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
  // gateway (web_gateway.h) forwards the browser's calls through it.
  std::shared_ptr<grpc::Channel> InProcessChannel();

  // Health → NOT_SERVING, long-lived streams end (after sending what is queued), then calls in
  // flight get up to `grace` to finish before they are cancelled. Idempotent.
  void Shutdown(std::chrono::milliseconds grace);

 private:
  Server(const ServerConfig& config, SessionCatalogue& catalogue, RigPort& rig, IndexCache& cache,
         const Authenticator& auth);

  StopSignal stopping_;
  StreamRegistry streams_;  // before the services, which hold slots in it
  ControlLoop control_loop_;
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
