// The web gateway ([web] listen): brdfd's browser front end (the operator console and the
// explorer, web/) and a JSON/HTTP door to the SAME gRPC services, on one HTTP(S) port.
//
//   POST /api/brdf.v1.<Service>/<Method>   body: the request as protobuf JSON (web_rpc.h)
//        unary methods   → 200 application/json, the response; errors → {"code","message"} with
//                          401 (no or unknown token), 403 (role), 400 (bad request or JSON),
//                          404, 409 (not in this state), 413 (body over kMaxBodyBytes), 429, 503…
//        ?omit=f1,f2     → (streams) those top-level fields of every answer left out
//        ?timeout_s=N    → (unary) the call's deadline, whole seconds from 1 to
//                          kLongestUnaryDeadline (default kUnaryDeadline), e.g. a lit sphere's
//                          first render on a large session
//        stream methods  → 200 text/event-stream: one "data: <json>" event per message, then
//                          "event: end" with {"code","message"} (OK or why the stream ended);
//                          a call refused before its first message is answered as a unary error.
//   GET  /api/about                         {"server": "brdfd" | "brdf-archive"}: which program
//                                           answers (the front end shows a rig's console or the
//                                           archive's read-only one); no token needed.
//   GET  /…                                 the built front end from the web root (index.html).
//
// Every API call is forwarded to the program's own gRPC server (brdfd's, or brdf-archive's) over an
// in-process channel with the request's "Authorization" header as the "authorization" metadata:
// authentication, roles, validation and limits are the gRPC server's own, call for call.
//
// Safety: bodies over kMaxBodyBytes are refused unread (413), reads and writes time out, at most
// kMaxStreams streams at a time (more: 429), a stream whose browser went away is cancelled within
// kKeepAlive; every answer carries a strict Content-Security-Policy (scripts only from the
// daemon, no inline script, no framing), X-Content-Type-Options: nosniff, Referrer-Policy:
// no-referrer, Cache-Control: no-store; no CORS headers (other origins cannot read answers).
// TLS from [server.tls] (the same certificate and key as gRPC) when configured.
#pragma once

#include <grpcpp/channel.h>

#include <atomic>
#include <chrono>
#include <memory>
#include <optional>
#include <string>
#include <thread>

#include "core/status.h"
#include "daemon/config/config.h"
#include "daemon/rpc/auth.h"

namespace httplib {
class Server;
}

namespace brdf::daemon {

class WebStreams;  // web_gateway.cc

// The built front end: [web] root, else the installed one, else this build tree's (a program
// run from its build directory, as the quick start and the tests do).
std::string DefaultWebRoot(const WebConfig& web);

class WebGateway {
 public:
  static constexpr std::size_t kMaxBodyBytes = 1 << 20;  // a plan is far smaller
  static constexpr int kMaxStreams = 12;
  static constexpr int kThreads = 24;  // HTTP worker threads (streams hold one each)
  static constexpr std::chrono::seconds kKeepAlive{5};
  static constexpr std::chrono::seconds kUnaryDeadline{60};
  static constexpr std::chrono::seconds kLongestUnaryDeadline{600};

  // Serves config.listen ("host:port"; port 0: any free port, see url()). `root` is the built
  // front end (a directory with index.html; missing: the API alone, GET / says how to build it).
  // `channel` leads to the program's own gRPC server (in process), whose calls the gateway admits
  // with that server's `auth` (which must outlive the gateway); `server` is its name ("brdfd" or
  // "brdf-archive", as GET /api/about says). kConfigurationError for an unreadable TLS file,
  // kIoError when the address cannot be bound.
  static Result<std::unique_ptr<WebGateway>> Start(const WebConfig& config,
                                                   const std::optional<TlsConfig>& tls,
                                                   const std::string& root,
                                                   std::shared_ptr<grpc::Channel> channel,
                                                   const Authenticator& auth,
                                                   const std::string& server = "brdfd");

  ~WebGateway();
  WebGateway(const WebGateway&) = delete;
  WebGateway& operator=(const WebGateway&) = delete;

  // "http://127.0.0.1:8080/" (the bound port; https with TLS).
  const std::string& url() const { return url_; }
  int port() const { return port_; }

  // Cancels the streams, stops accepting and waits for the worker threads. Idempotent.
  void Stop();

 private:
  WebGateway() = default;

  std::unique_ptr<httplib::Server> http_;
  std::shared_ptr<WebStreams> streams_;
  std::thread listener_;
  std::string url_;
  int port_ = 0;
  bool stopped_ = false;
};

}  // namespace brdf::daemon
