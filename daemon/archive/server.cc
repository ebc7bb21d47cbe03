#include "daemon/archive/server.h"

#include <absl/synchronization/mutex.h>
#include <grpcpp/server_builder.h>
#include <spdlog/spdlog.h>

#include "daemon/api/server.h"

namespace brdf::daemon {
namespace {

// Readings fetched per archive page when a cached session is brought up to date.
constexpr int kRefreshPage = 512;

}  // namespace

ArchiveServer::ArchiveServer(const ServerConfig& config,
                             std::shared_ptr<storage::ArchiveReader> archive,
                             const Authenticator& auth, Options options)
    : archive_(archive),
      options_(options),
      cache_(archive, options.cache),
      streams_(config, auth.enabled()),
      control_loop_(1),
      health_(stopping_, streams_),
      catalogue_(archive),
      control_(catalogue_, nullptr, auth, stopping_, streams_, "brdf-archive"),
      data_(catalogue_, auth, stopping_, streams_, "brdf-archive"),
      interpolation_(cache_, auth, stopping_, streams_),
      interpolate_loop_(interpolation_,
                        config.interpolate_threads > 0
                            ? config.interpolate_threads
                            : InterpolateLoopThreads(std::thread::hardware_concurrency()),
                        config.interpolate_cpus),
      reflection_v1_(ServedServices(), streams_),
      reflection_v1alpha_(ServedServices(), streams_) {}

ArchiveServer::~ArchiveServer() {
  Shutdown(std::chrono::seconds(1));
}

Result<std::unique_ptr<ArchiveServer>> ArchiveServer::Start(
    const ServerConfig& config, std::shared_ptr<storage::ArchiveReader> archive,
    const Authenticator& auth, Options options) {
  bool tls = false;
  Result<std::shared_ptr<grpc::ServerCredentials>> credentials =
      MakeServerCredentials(config, &tls);
  if (!credentials.ok()) return credentials.status();
  absl::SetMutexDeadlockDetectionMode(absl::OnDeadlockCycle::kIgnore);  // as brdfd (server.cc)

  std::unique_ptr<ArchiveServer> server(
      new ArchiveServer(config, std::move(archive), auth, options));
  server->health_.ServeOn(server->control_loop_);
  server->control_.ServeOn(server->control_loop_);
  int selected_port = 0;
  Result<std::string> address = BuildAndStartServer(
      config, *credentials, tls, auth,
      {&server->health_, &server->control_, &server->data_, &server->interpolation_,
       &server->reflection_v1_, &server->reflection_v1alpha_},
      server->interpolate_loop_, server->control_loop_, &server->server_, &selected_port);
  if (!address.ok()) return address.status();
  server->tls_ = tls;
  server->address_ = *address;
  server->refresher_ = std::thread([s = server.get()] { s->Refresh(); });
  server->health_.SetServingStatus("", true);
  for (const std::string& name : BrdfServiceNames()) server->health_.SetServingStatus(name, true);
  return server;
}

void ArchiveServer::Refresh() {
  bool failing = false;
  while (!stopping_.WaitFor(options_.refresh)) {
    for (const auto& [session, through] : cache_.HeldThrough()) {
      std::int64_t after = through;
      for (;;) {
        Result<std::vector<storage::ReadingRecord>> page =
            archive_->GetReadings(session, after, kRefreshPage);
        if (!page.ok()) {
          if (!failing) {
            spdlog::warn("bringing cached session {} up to date with the archive: {}", session,
                         page.status().ToString());
          }
          failing = true;
          break;
        }
        failing = false;
        for (const storage::ReadingRecord& r : *page) {
          cache_.OnReading(session, r);
          after = r.id;
        }
        if (static_cast<int>(page->size()) < kRefreshPage) break;
      }
    }
  }
}

std::shared_ptr<grpc::Channel> ArchiveServer::InProcessChannel() {
  grpc::ChannelArguments args;
  args.SetMaxReceiveMessageSize(-1);  // answers are limited by the services themselves
  return server_->InProcessChannel(args);
}

void ArchiveServer::Shutdown(std::chrono::milliseconds grace) {
  if (shut_down_ || !server_) return;
  shut_down_ = true;
  health_.SetServingStatus(false);
  stopping_.Stop();
  if (refresher_.joinable()) refresher_.join();
  interpolate_loop_.BeginShutdown();
  control_loop_.BeginShutdown();
  server_->Shutdown(std::chrono::system_clock::now() + grace);
  interpolate_loop_.Stop();
  control_loop_.Stop();
  server_->Wait();
}

}  // namespace brdf::daemon
