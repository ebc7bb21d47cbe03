#include "daemon/api/server.h"

#include <absl/synchronization/mutex.h>
#include <arpa/inet.h>
#include <grpcpp/resource_quota.h>
#include <grpcpp/security/server_credentials.h>
#include <grpcpp/server_builder.h>
#include <sched.h>
#include <spdlog/spdlog.h>
#include <sys/stat.h>

#include <algorithm>
#include <fstream>
#include <memory>
#include <sstream>
#include <thread>

#include "daemon/rpc/token_gate.h"

namespace brdf::daemon {
namespace {

// The control plane's threads (control_loop.h): one answers while the other may wait on the
// store (SubmitPlan's commit).
constexpr int kControlThreads = 2;

// The stream pump's threads (stream_pump.h): WatchSession and StreamReadings, however many are
// open. A step writes one message or reads one store page; a few threads keep one slow page
// from holding up the others.
constexpr int kStreamPumpThreads = 4;

constexpr const char* kBrdfServices[] = {"brdf.v1.Control", "brdf.v1.Data",
                                         "brdf.v1.Interpolation"};

// Every service the server registers (reflection's list_services).
std::vector<std::string> ServedServices() {
  std::vector<std::string> names(std::begin(kBrdfServices), std::end(kBrdfServices));
  names.push_back("grpc.health.v1.Health");
  names.push_back("grpc.reflection.v1.ServerReflection");
  names.push_back("grpc.reflection.v1alpha.ServerReflection");
  return names;
}

// Reads a PEM file and checks that it holds a block of the expected kind ("CERTIFICATE",
// "PRIVATE KEY": also matches "EC PRIVATE KEY", "RSA PRIVATE KEY"). gRPC itself only says that
// the port could not be opened when a file is not PEM, so the check here names the file.
Result<std::string> ReadPem(const std::string& path, const std::string& key,
                            const std::string& block) {
  std::ifstream in(path, std::ios::binary);
  if (!in) {
    return ConfigurationError("config " + key + ": cannot read \"" + path +
                              "\"; check the path and that brdfd may read it");
  }
  std::ostringstream text;
  text << in.rdbuf();
  if (text.str().empty()) {
    return ConfigurationError("config " + key + ": \"" + path + "\" is empty; give a PEM file");
  }
  if (text.str().find(block + "-----") == std::string::npos) {
    return ConfigurationError("config " + key + ": \"" + path + "\" holds no PEM \"" + block +
                              "\" block; give a PEM file (-----BEGIN " + block + "-----)");
  }
  return text.str();
}

// A private key others may read is a key others may copy.
void WarnIfReadableByOthers(const std::string& path) {
  struct stat info {};
  if (::stat(path.c_str(), &info) == 0 && (info.st_mode & (S_IRWXG | S_IRWXO)) != 0) {
    spdlog::warn(
        "the TLS private key {} is accessible to its group or others (mode {:o}); "
        "chmod 600 it",
        path, info.st_mode & 0777);
  }
}

std::string HostOf(const std::string& listen) {
  const std::size_t colon = listen.rfind(':');
  std::string host = colon == std::string::npos ? listen : listen.substr(0, colon);
  if (host.size() >= 2 && host.front() == '[' && host.back() == ']') {
    host = host.substr(1, host.size() - 2);
  }
  return host;
}

// Every CPU of [server] interpolate_cpus must be one brdfd may run on (its affinity mask: the
// machine's CPUs, narrowed by taskset or the service's CPUAffinity).
Status CheckCpusAvailable(const std::vector<int>& cpus) {
  if (cpus.empty()) return Status::Ok();
  cpu_set_t allowed;
  CPU_ZERO(&allowed);
  if (::sched_getaffinity(0, sizeof(allowed), &allowed) != 0) return Status::Ok();  // cannot tell
  std::string available;
  for (int c = 0; c < CPU_SETSIZE; ++c) {
    if (CPU_ISSET(c, &allowed)) available += (available.empty() ? "" : ", ") + std::to_string(c);
  }
  for (int cpu : cpus) {
    if (cpu < 0 || cpu >= CPU_SETSIZE || !CPU_ISSET(cpu, &allowed)) {
      return ConfigurationError("config server.interpolate_cpus: CPU " + std::to_string(cpu) +
                                " is not one brdfd may run on (it may use CPUs " + available +
                                "); fix [server] interpolate_cpus");
    }
  }
  return Status::Ok();
}

// The server's credentials from [server] and [server.tls]: TLS (client certificates required
// when client_ca is set; `tls` true) or plaintext that still takes the token gate (a warning is
// logged when a non-loopback address is served in plaintext). kConfigurationError naming the key
// when a TLS file cannot be read or holds no PEM block of its kind.
Result<std::shared_ptr<grpc::ServerCredentials>> MakeServerCredentials(const ServerConfig& config,
                                                                       bool* tls) {
  std::shared_ptr<grpc::ServerCredentials> credentials;
  *tls = false;
  if (config.tls.has_value()) {
    BRDF_ASSIGN_OR_RETURN(std::string cert,
                          ReadPem(config.tls->cert, "server.tls.cert", "CERTIFICATE"));
    BRDF_ASSIGN_OR_RETURN(std::string key,
                          ReadPem(config.tls->key, "server.tls.key", "PRIVATE KEY"));
    WarnIfReadableByOthers(config.tls->key);
    grpc::SslServerCredentialsOptions ssl(GRPC_SSL_DONT_REQUEST_CLIENT_CERTIFICATE);
    ssl.pem_key_cert_pairs.push_back({key, cert});
    if (!config.tls->client_ca.empty()) {
      BRDF_ASSIGN_OR_RETURN(std::string ca,
                            ReadPem(config.tls->client_ca, "server.tls.client_ca", "CERTIFICATE"));
      ssl.pem_root_certs = ca;
      ssl.client_certificate_request = GRPC_SSL_REQUEST_AND_REQUIRE_CLIENT_CERTIFICATE_AND_VERIFY;
    }
    credentials = grpc::SslServerCredentials(ssl);
    *tls = true;
  } else {
    // Plaintext as gRPC's xDS credentials with the insecure fallback (no xDS server here, so
    // plaintext is all they do): unlike InsecureServerCredentials() they take the token gate.
    credentials = grpc::XdsServerCredentials(grpc::InsecureServerCredentials());
    if (!IsLoopbackAddress(config.listen)) {
      spdlog::warn(
          "serving {} in PLAINTEXT on a non-loopback address: bearer tokens and data cross the "
          "network unencrypted; configure [server.tls] (cert, key) or listen on 127.0.0.1",
          config.listen);
    }
  }
  return credentials;
}

// After BuildAndStart (`built`: it returned a server): the address served, with the port bound
// ("127.0.0.1:43123", "unix:/run/brdfd.sock"); kIoError naming the address when nothing was bound.
Result<std::string> BoundAddress(const ServerConfig& config, bool built, int selected_port,
                                 bool tls) {
  const bool unix_socket = config.listen.rfind("unix:", 0) == 0;
  if (!built || (!unix_socket && selected_port == 0)) {
    return IoError("cannot listen on " + config.listen +
                   (tls ? " with TLS (address in use, not allowed, no such interface, or the "
                          "certificate and key in [server.tls] do not form a valid pair)"
                        : " (address in use, not allowed, or no such interface)") +
                   "; change [server] listen or stop the process that holds it");
  }
  if (unix_socket) return config.listen;
  return config.listen.substr(0, config.listen.rfind(':') + 1) + std::to_string(selected_port);
}

}  // namespace

bool IsLoopbackAddress(const std::string& listen) {
  if (listen.rfind("unix:", 0) == 0) return true;
  const std::string host = HostOf(listen);
  if (host == "localhost") return true;
  // Literal addresses only: a host NAME such as "127.example.org" may resolve anywhere.
  in_addr v4{};
  if (::inet_pton(AF_INET, host.c_str(), &v4) == 1) {
    return (ntohl(v4.s_addr) >> 24) == 127;
  }
  in6_addr v6{};
  if (::inet_pton(AF_INET6, host.c_str(), &v6) == 1) {
    if (IN6_IS_ADDR_LOOPBACK(&v6)) return true;
    return IN6_IS_ADDR_V4MAPPED(&v6) && v6.s6_addr[12] == 127;  // ::ffff:127.x.y.z
  }
  return false;
}

int InterpolateLoopThreads(unsigned cores) {
  return static_cast<int>(std::clamp(cores / 2, 1U, 8U));
}

Server::Server(const ServerConfig& config, const BackEnd& back_end, const Authenticator& auth)
    : streams_(config, auth.enabled()),
      control_loop_(kControlThreads),
      pump_(kStreamPumpThreads),
      health_(stopping_, streams_),
      control_(*back_end.catalogue, back_end.rig, auth, stopping_, streams_, pump_,
               back_end.program),
      data_(*back_end.catalogue, auth, stopping_, streams_, pump_, back_end.program,
            back_end.exports),
      interpolation_(*back_end.cache, auth, stopping_, streams_),
      interpolate_loop_(interpolation_,
                        config.interpolate_threads > 0
                            ? config.interpolate_threads
                            : InterpolateLoopThreads(std::thread::hardware_concurrency()),
                        config.interpolate_cpus),
      reflection_v1_(ServedServices(), streams_),
      reflection_v1alpha_(ServedServices(), streams_) {}

Server::~Server() {
  Shutdown(std::chrono::seconds(1));
}

Result<std::unique_ptr<Server>> Server::Start(const ServerConfig& config, const BackEnd& back_end,
                                              const Authenticator& auth) {
  bool tls = false;
  BRDF_ASSIGN_OR_RETURN(std::shared_ptr<grpc::ServerCredentials> credentials,
                        MakeServerCredentials(config, &tls));

  // Debian builds Abseil without NDEBUG, which leaves absl::Mutex's lock-order (deadlock) graph
  // on: every lock gRPC takes records the lock in a global graph, about a tenth of the CPU of a
  // small call. Upstream release builds have it off; so do we (process-wide, before any call).
  absl::SetMutexDeadlockDetectionMode(absl::OnDeadlockCycle::kIgnore);
  // glibc's arenas capped before the server's threads start (rpc/memory_budget.h).
  ConfigureAllocator();

  if (Status st = CheckCpusAvailable(config.interpolate_cpus); !st.ok()) return st;
  std::unique_ptr<Server> server(new Server(config, back_end, auth));
  server->health_.ServeOn(server->control_loop_);
  server->control_.ServeOn(server->control_loop_);
  if (Status st = server->Listen(config, credentials, tls, auth); !st.ok()) return st;
  server->LogLimits(config);
  server->health_.SetServingStatus("", true);
  for (const char* name : kBrdfServices) server->health_.SetServingStatus(name, true);
  return server;
}

Status Server::Listen(const ServerConfig& config,
                      const std::shared_ptr<grpc::ServerCredentials>& credentials, bool tls,
                      const Authenticator& auth) {
  grpc::ServerBuilder builder;
  credentials->SetAuthMetadataProcessor(std::make_shared<TokenGate>(auth));
  int selected_port = 0;
  builder.AddListeningPort(config.listen, credentials, &selected_port);
  // One server per address: without SO_REUSEPORT a second one's bind fails instead of sharing
  // the port (and answering some of the first one's calls).
  builder.AddChannelArgument(GRPC_ARG_ALLOW_REUSEPORT, 0);
  builder.SetMaxReceiveMessageSize(kMaxReceiveMessageBytes);
  grpc::ResourceQuota quota("brdfd");
  quota.SetMaxThreads(ServerThreadCap(config));
  builder.SetResourceQuota(quota);
  for (grpc::Service* service : std::initializer_list<grpc::Service*>{
           &health_, &control_, &data_, &interpolation_, &reflection_v1_, &reflection_v1alpha_}) {
    builder.RegisterService(service);
  }
  interpolate_loop_.AddQueues(builder);
  control_loop_.AddQueue(builder);
  server_ = builder.BuildAndStart();
  BRDF_ASSIGN_OR_RETURN(std::string address,
                        BoundAddress(config, server_ != nullptr, selected_port, tls));
  interpolate_loop_.Start();
  control_loop_.Start();
  tls_ = tls;
  port_ = selected_port;
  address_ = address;
  return Status::Ok();
}

void Server::LogLimits(const ServerConfig& config) const {
  spdlog::info(
      "limits: requests up to {} bytes (larger: RESOURCE_EXHAUSTED), InterpolateBatch up to {} "
      "directions in chunks of up to {} results, notes up to {} bytes, pages up to {} sessions, "
      "open streams up to {} per token, {} analyst, {} operator, {} without a token (a stream "
      "not read for {} s is cancelled), heavy calls within a memory budget of {} MB, {} call "
      "threads, WatchSession and StreamReadings on {} pump thread(s), control plane on {} "
      "thread(s), "
      "Interpolate on {} loop thread(s){}",
      kMaxReceiveMessageBytes, kMaxBatchDirections, kMaxChunkSize, kMaxNoteBytes, kMaxPageSize,
      config.max_streams_per_token, config.max_streams_analyst, config.max_streams_operator,
      config.max_streams_unauthenticated, config.stream_stall_timeout_s, config.memory_budget_mb,
      ServerThreadCap(config), pump_.threads(), control_loop_.threads(),
      interpolate_loop_.threads(),
      tls_ ? (config.tls->client_ca.empty() ? "; TLS" : "; TLS, client certificates required")
           : "; plaintext");
}

std::shared_ptr<grpc::Channel> Server::InProcessChannel() {
  grpc::ChannelArguments args;
  args.SetMaxReceiveMessageSize(-1);  // answers are limited by the services themselves
  return server_->InProcessChannel(args);
}

void Server::Shutdown(std::chrono::milliseconds grace) {
  if (shut_down_ || !server_) return;
  shut_down_ = true;
  health_.SetServingStatus(false);
  stopping_.Stop();
  pump_.WakeAll();  // the pump's waiting streams see the stop now
  interpolate_loop_.BeginShutdown();
  control_loop_.BeginShutdown();
  server_->Shutdown(std::chrono::system_clock::now() + grace);
  interpolate_loop_.Stop();
  control_loop_.Stop();
  server_->Wait();
  pump_.Stop();  // after the server: its cancelled streams finish on the pump
}

}  // namespace brdf::daemon
