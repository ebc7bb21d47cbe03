// What brdfd and brdf-archive do alike once their back end is open: the gRPC server over it
// (api/server.h), the web gateway in front of it ([web] listen; gateway/http_server.h), the lines
// on stdout that say where they serve, systemd's READY=1 and STOPPING=1 (when built with
// libsystemd), and at SIGTERM / SIGINT the stop: the back end's own first, then the web gateway,
// then the server.
#pragma once

#include <signal.h>

#include <chrono>
#include <functional>
#include <memory>
#include <string>

#include "core/status.h"
#include "daemon/api/server.h"
#include "daemon/config/config.h"
#include "daemon/gateway/http_server.h"
#include "daemon/rpc/auth.h"

namespace brdf::daemon {

// How a program names itself and what its stop means, in its lines and logs.
struct Program {
  std::string name;      // "brdfd": "brdfd listening on <address>"
  std::string web_name;  // "web console": "brdfd web console on <url>"
  std::string stopping;  // what a stop signal does first, for the log
  std::string lost;      // what a second stop signal (an exit at once) loses, for the log
};

class Serving {
 public:
  // Starts the server on config.server over `back_end` (its exports' kept interpolants bounded by
  // config's [export]), then, with [web] listen, the web gateway
  // (printing "<name> <web_name> on <url>"); then prints "<name> listening on <address>" and
  // tells systemd READY=1. A failure is logged and returned, with nothing left running. `auth`
  // and the back end's parts must outlive the Serving.
  static Result<std::unique_ptr<Serving>> Start(const Program& program, const Config& config,
                                                const BackEnd& back_end, const Authenticator& auth);
  ~Serving();  // Stop(), if not done before
  Serving(const Serving&) = delete;
  Serving& operator=(const Serving&) = delete;

  const Server& server() const { return *server_; }

  // Waits for SIGTERM / SIGINT (`stop_signals`, blocked in every thread: config/startup.h), then
  // runs `stop_back_end` on a thread of its own (a second signal meanwhile exits the process at
  // once, with 1) and stops the web gateway and the server.
  void ServeUntilStopped(const sigset_t& stop_signals, const std::function<void()>& stop_back_end);

 private:
  Serving() = default;
  // The web gateway and the server, in that order. Idempotent.
  void Stop();

  Program program_;
  std::unique_ptr<Server> server_;
  std::unique_ptr<WebGateway> web_;
};

}  // namespace brdf::daemon
