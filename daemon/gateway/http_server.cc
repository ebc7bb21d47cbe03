#include "daemon/gateway/http_server.h"

#include <httplib.h>
#include <spdlog/spdlog.h>
#include <sys/socket.h>

#include <deque>
#include <filesystem>
#include <fstream>
#include <set>

#include "core/client_text.h"
#include "core/mutex.h"
#include "daemon/gateway/json_rpc.h"

namespace brdf::daemon {
namespace {

// Messages a stream may hold for a browser that reads slower than the daemon writes; the gRPC
// call waits beyond it (the daemon's own flow control then applies).
constexpr std::size_t kMaxQueuedMessages = 64;
// How long a stream call may take to produce its first message or its refusal before the
// browser gets the 200 and the events.
constexpr std::chrono::seconds kFirstMessageWait{30};

// Debian's cpp-httplib compresses answers whose type is exactly "application/json",
// "application/javascript" or text/* when the browser accepts br or gzip, with brotli at its
// slowest quality (the 5 MB bundle took over 20 s). The types with a charset parameter are
// sent as they are: the API's answers are small or streamed, and the daemon serves the bundle
// from the same machine or a lab network.
constexpr const char* kJson = "application/json; charset=utf-8";
constexpr const char* kJavaScript = "application/javascript; charset=utf-8";

constexpr const char* kContentSecurityPolicy =
    "default-src 'none'; script-src 'self'; style-src 'self' 'unsafe-inline'; "
    "img-src 'self' data: blob:; connect-src 'self'; font-src 'self'; worker-src 'self' blob:; "
    "base-uri 'none'; form-action 'none'; frame-ancestors 'none'";

// One server-streaming call in flight: a reader thread moves the gRPC answers into `queue`, the
// HTTP worker writes them out as events.
struct StreamCall {
  grpc::ClientContext context;
  Mutex mu;
  CondVar cv;
  std::deque<std::string> queue GUARDED_BY(mu);
  bool done GUARDED_BY(mu) = false;
  bool abandoned GUARDED_BY(mu) = false;  // the browser left or the gateway stops
  grpc::Status status GUARDED_BY(mu);
  std::thread reader;

  void Abandon() {
    {
      MutexLock lock(mu);
      abandoned = true;
    }
    cv.NotifyAll();
    context.TryCancel();
  }
};

bool ParseListen(const std::string& listen, std::string* host, int* port) {
  const std::size_t colon = listen.rfind(':');
  if (colon == std::string::npos) return false;
  *host = listen.substr(0, colon);
  if (host->size() >= 2 && host->front() == '[' && host->back() == ']') {
    *host = host->substr(1, host->size() - 2);
  }
  try {
    *port = std::stoi(listen.substr(colon + 1));
  } catch (...) {
    return false;
  }
  return true;
}

// SO_REUSEADDR only (httplib's default adds SO_REUSEPORT, which would let a second brdfd bind
// the same port and take half the connections).
void SocketOptions(int sock) {
  int yes = 1;
  ::setsockopt(sock, SOL_SOCKET, SO_REUSEADDR, &yes, sizeof yes);
}

void ReplyError(httplib::Response& res, const grpc::Status& status) {
  res.status = HttpStatusFor(status.error_code());
  res.set_content(StatusJson(status), kJson);
}

}  // namespace

// The streams in flight, so that Stop can cancel them and a cap holds.
class WebStreams {
 public:
  bool Admit(StreamCall* call) {
    MutexLock lock(mu_);
    if (stopping_ || static_cast<int>(live_.size()) >= WebGateway::kMaxStreams) return false;
    live_.insert(call);
    return true;
  }
  void Remove(StreamCall* call) {
    MutexLock lock(mu_);
    live_.erase(call);
  }
  void CancelAll() {
    MutexLock lock(mu_);
    stopping_ = true;
    for (StreamCall* call : live_) call->Abandon();
  }

 private:
  Mutex mu_;
  std::set<StreamCall*> live_ GUARDED_BY(mu_);
  bool stopping_ GUARDED_BY(mu_) = false;
};

namespace {

// ?timeout_s=N: a unary call's deadline instead of kUnaryDeadline.
grpc::Status ParseTimeout(const httplib::Request& req, std::chrono::seconds* deadline) {
  if (!req.has_param("timeout_s")) return grpc::Status::OK;
  const std::string value = req.get_param_value("timeout_s");
  const long longest = static_cast<long>(WebGateway::kLongestUnaryDeadline.count());
  long seconds = 0;
  bool digits = !value.empty() && value.size() <= 4;
  for (const char c : value) {
    digits = digits && c >= '0' && c <= '9';
    if (digits) seconds = seconds * 10 + (c - '0');
  }
  if (!digits || seconds < 1 || seconds > longest) {
    return grpc::Status(grpc::INVALID_ARGUMENT, "timeout_s: give whole seconds from 1 to " +
                                                    std::to_string(longest) + " (got \"" +
                                                    PrintablePrefix(value) + "\")");
  }
  *deadline = std::chrono::seconds(seconds);
  return grpc::Status::OK;
}

// The stream's gRPC call, on a thread of its own: answers queue on `call` (at most
// kMaxQueuedMessages ahead of the browser), then the final status.
void StartReader(const std::shared_ptr<JsonRpc>& rpc, StreamCall* call, const WebMethod& method,
                 const httplib::Request& req, OmitFields omit) {
  call->reader = std::thread([rpc, call, &method, body = req.body, omit = std::move(omit),
                              auth = req.get_header_value("Authorization")] {
    grpc::Status st =
        rpc->Stream(method, body, auth, omit, &call->context, [call](std::string json) {
          MutexLock lock(call->mu);
          call->cv.Wait(call->mu, [call]() REQUIRES(call->mu) {
            return call->abandoned || call->queue.size() < kMaxQueuedMessages;
          });
          if (call->abandoned) return false;
          call->queue.push_back(std::move(json));
          call->cv.NotifyAll();
          return true;
        });
    MutexLock lock(call->mu);
    call->done = true;
    call->status = std::move(st);
    call->cv.NotifyAll();
  });
}

// The call's refusal when it was refused up front (no token, wrong role, bad request: it ended
// without an answer within kFirstMessageWait); OK otherwise.
grpc::Status RefusedUpFront(StreamCall& call) {
  MutexLock lock(call.mu);
  call.cv.WaitFor(call.mu, kFirstMessageWait,
                  [&]() REQUIRES(call.mu) { return !call.queue.empty() || call.done; });
  if (call.queue.empty() && call.done && !call.status.ok()) return call.status;
  return grpc::Status::OK;
}

// The next server-sent event of `call` (an answer, the end with its status, or a keep-alive
// that also finds out whether the browser is still there); false when the call was abandoned.
bool NextEvent(StreamCall& call, std::string* event, bool* end) {
  MutexLock lock(call.mu);
  call.cv.WaitFor(call.mu, WebGateway::kKeepAlive, [&]() REQUIRES(call.mu) {
    return !call.queue.empty() || call.done || call.abandoned;
  });
  if (!call.queue.empty()) {
    *event = "data: " + call.queue.front() + "\n\n";
    call.queue.pop_front();
    call.cv.NotifyAll();
  } else if (call.done) {
    *event = "event: end\ndata: " + StatusJson(call.status) + "\n\n";
    *end = true;
  } else if (call.abandoned) {
    return false;
  } else {
    *event = ": keep-alive\n\n";
  }
  return true;
}

void ServeStream(const std::shared_ptr<JsonRpc>& rpc, const std::shared_ptr<WebStreams>& streams,
                 const WebMethod& method, const httplib::Request& req, httplib::Response& res) {
  if (req.has_param("timeout_s")) {
    ReplyError(res, grpc::Status(grpc::INVALID_ARGUMENT,
                                 "timeout_s: a stream has no deadline (it ends when its answer "
                                 "does or the page goes away); leave it out"));
    return;
  }
  OmitFields omit;
  if (grpc::Status st = ParseOmit(method, req.get_param_value("omit"), &omit); !st.ok()) {
    ReplyError(res, st);
    return;
  }
  auto call = std::make_shared<StreamCall>();
  if (!streams->Admit(call.get())) {
    ReplyError(res, grpc::Status(grpc::RESOURCE_EXHAUSTED,
                                 "too many live streams on the web gateway (at most " +
                                     std::to_string(WebGateway::kMaxStreams) +
                                     "); close other console tabs and retry"));
    return;
  }
  StartReader(rpc, call.get(), method, req, std::move(omit));
  auto finish = [streams, call] {
    call->Abandon();
    if (call->reader.joinable()) call->reader.join();
    streams->Remove(call.get());
  };
  if (grpc::Status refused = RefusedUpFront(*call); !refused.ok()) {
    finish();
    ReplyError(res, refused);
    return;
  }
  res.set_header("X-Accel-Buffering", "no");
  res.set_chunked_content_provider(
      "text/event-stream",
      [call](std::size_t, httplib::DataSink& sink) {
        std::string event;
        bool end = false;
        if (!NextEvent(*call, &event, &end)) return false;
        if (!sink.write(event.data(), event.size())) return false;
        if (end) sink.done();
        return true;
      },
      [finish](bool) { finish(); });
}

void ServeApi(const std::shared_ptr<JsonRpc>& rpc, const std::shared_ptr<WebStreams>& streams,
              const httplib::Request& req, httplib::Response& res) {
  const std::string name = req.matches[1];
  const WebMethod* method = FindWebMethod(name);
  if (method == nullptr) {
    ReplyError(res, grpc::Status(grpc::UNIMPLEMENTED,
                                 "no method " + PrintablePrefix(name) +
                                     " in brdf.v1; see brdf.proto (e.g. brdf.v1.Control/"
                                     "ListSessions)"));
    res.status = 404;
    return;
  }
  const std::string type = req.get_header_value("Content-Type");
  if (!req.body.empty() && type.rfind("application/json", 0) != 0) {
    ReplyError(res, grpc::Status(grpc::INVALID_ARGUMENT,
                                 "send the request as Content-Type: application/json"));
    res.status = 415;
    return;
  }
  if (method->server_streaming) {
    ServeStream(rpc, streams, *method, req, res);
    return;
  }
  std::chrono::seconds deadline = WebGateway::kUnaryDeadline;
  if (grpc::Status st = ParseTimeout(req, &deadline); !st.ok()) {
    ReplyError(res, st);
    return;
  }
  std::string out;
  const grpc::Status st =
      rpc->Unary(*method, req.body, req.get_header_value("Authorization"), deadline, &out);
  if (!st.ok()) {
    ReplyError(res, st);
    return;
  }
  res.set_content(out, kJson);
}

}  // namespace

std::string DefaultWebRoot(const WebConfig& web) {
  if (!web.root.empty()) return web.root;
#if defined(BRDF_WEB_INSTALL_DIR) && defined(BRDF_WEB_BUILD_DIR)
  if (std::ifstream(std::string(BRDF_WEB_INSTALL_DIR) + "/index.html")) return BRDF_WEB_INSTALL_DIR;
  return BRDF_WEB_BUILD_DIR;
#else
  return {};
#endif
}

namespace {

// The HTTPS server with [server.tls]'s certificate and key (client certificates required when
// client_ca is set), or a plain HTTP server.
Result<std::unique_ptr<httplib::Server>> MakeHttpServer(const std::optional<TlsConfig>& tls) {
  if (!tls.has_value()) return std::make_unique<httplib::Server>();
  for (const std::string* path : {&tls->cert, &tls->key}) {
    if (!std::ifstream(*path)) {
      return ConfigurationError("config server.tls: cannot read \"" + *path +
                                "\" for the web gateway; check the path and its mode");
    }
  }
  auto https = std::make_unique<httplib::SSLServer>(
      tls->cert.c_str(), tls->key.c_str(),
      tls->client_ca.empty() ? nullptr : tls->client_ca.c_str());
  if (!https->is_valid()) {
    return ConfigurationError(
        "config server.tls: the web gateway cannot use the certificate and key (not a "
        "matching PEM pair?)");
  }
  return std::unique_ptr<httplib::Server>(std::move(https));
}

// Threads, sockets, limits, time-outs and the security headers of every answer.
void ConfigureTransport(httplib::Server& http, bool tls) {
  http.new_task_queue = [] { return new httplib::ThreadPool(WebGateway::kThreads); };
  http.set_socket_options(SocketOptions);
  // A stream writes one small event at a time, which Nagle's algorithm would hold back for the
  // browser's delayed ACK (~40 ms an event: 2.4 s for 87 readings).
  http.set_tcp_nodelay(true);
  http.set_payload_max_length(WebGateway::kMaxBodyBytes);
  http.set_read_timeout(10, 0);
  http.set_write_timeout(10, 0);
  http.set_keep_alive_timeout(2);
  http.set_keep_alive_max_count(100);
  httplib::Headers headers = {
      {"Content-Security-Policy", kContentSecurityPolicy},
      {"X-Content-Type-Options", "nosniff"},
      {"X-Frame-Options", "DENY"},
      {"Referrer-Policy", "no-referrer"},
      {"Cross-Origin-Opener-Policy", "same-origin"},
      {"Cross-Origin-Resource-Policy", "same-origin"},
      {"Cache-Control", "no-store"},
  };
  if (tls) headers.emplace("Strict-Transport-Security", "max-age=31536000");
  http.set_default_headers(headers);
}

// POST /api/brdf.v1.<Service>/<Method>, GET /api/about, and a refusal for any other /api/ GET.
void RouteApi(httplib::Server& http, const std::shared_ptr<JsonRpc>& rpc,
              const std::shared_ptr<WebStreams>& streams, const std::string& server) {
  http.Post(R"(/api/(brdf\.v1\.[A-Za-z]+/[A-Za-z]+))",
            [rpc, streams](const httplib::Request& req, httplib::Response& res) {
              ServeApi(rpc, streams, req, res);
            });
  // Registered before the catch-all below: the first matching route answers.
  const std::string about = R"({"server":")" + server + R"("})";
  http.Get("/api/about", [about](const httplib::Request&, httplib::Response& res) {
    res.set_content(about, kJson);
  });
  http.Get(R"(/api/.*)", [](const httplib::Request&, httplib::Response& res) {
    ReplyError(res, grpc::Status(grpc::INVALID_ARGUMENT,
                                 "API calls are POST /api/brdf.v1.<Service>/<Method> with a "
                                 "JSON body"));
    res.status = 405;
  });
}

// The built front end under `root`, or at / a page saying how to build it. True when built.
bool RouteFrontEnd(httplib::Server& http, const std::string& root) {
  const bool have_root = !root.empty() && std::filesystem::exists(root + "/index.html");
  if (have_root) http.set_mount_point("/", root);
  http.set_file_extension_and_mimetype_mapping("js", kJavaScript);
  http.Get("/", [have_root, root](const httplib::Request&, httplib::Response& res) {
    res.status = have_root ? 404 : 503;
    res.set_content("brdfd's web console is not built (no index.html in \"" + root +
                        "\"): install nodejs and npm (deploy/install-deps.sh) and rebuild, or "
                        "set [web] root. The JSON API works without it.\n",
                    "text/plain; charset=utf-8");
  });
  return have_root;
}

// Bodies for errors httplib answers itself (413 as the API's JSON), internal errors, the log.
void HandleErrors(httplib::Server& http) {
  http.set_error_handler([](const httplib::Request&, httplib::Response& res) {
    if (!res.body.empty()) return;
    if (res.status == 413) {
      ReplyError(res,
                 grpc::Status(grpc::RESOURCE_EXHAUSTED,
                              "request body over " + std::to_string(WebGateway::kMaxBodyBytes) +
                                  " bytes; send a smaller request"));
      res.status = 413;
      return;
    }
    res.set_content("HTTP " + std::to_string(res.status) + "\n", "text/plain; charset=utf-8");
  });
  http.set_exception_handler(
      [](const httplib::Request& req, httplib::Response& res, std::exception_ptr) {
        spdlog::error("web gateway: internal error answering {} {}", req.method, req.path);
        ReplyError(res, grpc::Status(grpc::INTERNAL, "internal error in the web gateway"));
      });
  http.set_logger([](const httplib::Request& req, const httplib::Response& res) {
    spdlog::debug("web {} {} {} from {}", req.method, req.path, res.status, req.remote_addr);
  });
}

// Binds host:port (0: any free port); the port bound, or 0 when nothing could be bound.
int Bind(httplib::Server& http, const std::string& host, int port) {
  if (port == 0) {
    port = http.bind_to_any_port(host);
    return port < 0 ? 0 : port;
  }
  return http.bind_to_port(host, port) ? port : 0;
}

}  // namespace

Result<std::unique_ptr<WebGateway>> WebGateway::Start(
    const WebConfig& config, const std::optional<TlsConfig>& tls, const std::string& root,
    std::shared_ptr<grpc::Channel> channel, const Authenticator& auth, const std::string& server) {
  std::string host;
  int port = 0;
  if (!ParseListen(config.listen, &host, &port)) {
    return ConfigurationError("config web.listen: \"" + config.listen +
                              "\" is not host:port; give e.g. \"127.0.0.1:8080\"");
  }
  BRDF_ASSIGN_OR_RETURN(std::unique_ptr<httplib::Server> made, MakeHttpServer(tls));
  std::unique_ptr<WebGateway> gateway(new WebGateway());
  gateway->http_ = std::move(made);
  gateway->streams_ = std::make_shared<WebStreams>();
  httplib::Server& http = *gateway->http_;
  ConfigureTransport(http, tls.has_value());
  RouteApi(http, std::make_shared<JsonRpc>(std::move(channel), auth), gateway->streams_, server);
  const bool have_root = RouteFrontEnd(http, root);
  HandleErrors(http);
  port = Bind(http, host, port);
  if (port == 0) {
    return IoError("cannot listen on " + config.listen +
                   " for the web console (address in use, not allowed, or no such interface); "
                   "change [web] listen or stop the process that holds it");
  }
  gateway->port_ = port;
  const bool v6 = host.find(':') != std::string::npos;
  gateway->url_ = std::string(tls ? "https" : "http") + "://" + (v6 ? "[" + host + "]" : host) +
                  ":" + std::to_string(port) + "/";
  gateway->listener_ = std::thread([&http] { http.listen_after_bind(); });
  spdlog::info("web console on {} ({}; requests up to {} bytes, {} streams)", gateway->url_,
               have_root ? "front end from " + root : "API only: front end not built",
               kMaxBodyBytes, kMaxStreams);
  return gateway;
}

WebGateway::~WebGateway() {
  Stop();
}

void WebGateway::Stop() {
  if (stopped_ || !http_) return;
  stopped_ = true;
  streams_->CancelAll();
  http_->stop();
  if (listener_.joinable()) listener_.join();
}

}  // namespace brdf::daemon
