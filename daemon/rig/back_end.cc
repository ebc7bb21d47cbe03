#include "daemon/rig/back_end.h"

#include <spdlog/spdlog.h>

#include <utility>
#include <vector>

#include "core/adaptive/interpolated_model.h"

namespace brdf::daemon {

Result<std::unique_ptr<RigBackEnd>> RigBackEnd::Open(const Config& config,
                                                     std::unique_ptr<Rig> rig) {
  std::unique_ptr<RigBackEnd> back_end(new RigBackEnd());
  Result<std::unique_ptr<storage::SessionStore>> opened =
      storage::SessionStore::Open(config.storage.database);
  if (!opened.ok()) {
    spdlog::critical("cannot open the database {}: {}", config.storage.database,
                     opened.status().ToString());
    return opened.status();
  }
  back_end->store_ = std::move(*opened);
  if (Status st = back_end->StartShipping(config); !st.ok()) return st;
  if (Status st = back_end->StartManager(config, std::move(rig)); !st.ok()) return st;

  SessionManager& manager = *back_end->manager_;
  back_end->cache_ =
      std::make_unique<IndexCache>(back_end->store_, IndexCacheOptionsFrom(config),
                                   [&manager](SessionId session) { return manager.Plan(session); });
  IndexCache& cache = *back_end->cache_;
  back_end->cache_listener_ = manager.AddReadingListener(
      [&cache](SessionId session, const storage::ReadingRecord& reading) {
        cache.OnReading(session, reading);
      });
  back_end->catalogue_ = std::make_unique<RigCatalogue>(manager);
  back_end->port_ = std::make_unique<ManagerRigPort>(manager);
  return back_end;
}

Status RigBackEnd::StartShipping(const Config& config) {
  if (!config.archive.enabled()) {
    Status off = store_->SetArchiveShipping(false);
    if (!off.ok()) spdlog::critical("cannot turn off the archive outbox: {}", off.ToString());
    return off;
  }
  // Its own thread, never in the executor's way (engine/shipper.h).
  ArchiveShipper::Options options;
  options.credentials_path = config.archive.credentials;
  options.rig = RigName(config);
  options.batch_readings = config.archive.batch_readings;
  options.retry = std::chrono::milliseconds(config.archive.retry_ms);
  options.rig_description = ToRigDescription(config);
  Result<std::unique_ptr<ArchiveShipper>> started = ArchiveShipper::Start(store_, options);
  if (!started.ok()) {
    spdlog::critical("cannot start shipping to the archive: {}", started.status().ToString());
    return started.status();
  }
  shipper_ = std::move(*started);
  spdlog::info("shipping to the archive (credentials from {}) as rig \"{}\"",
               config.archive.credentials, RigName(config));
  return Status::Ok();
}

Status RigBackEnd::StartManager(const Config& config, std::unique_ptr<Rig> rig) {
  SessionManager::Options options;
  if (shipper_ != nullptr) {
    options.archive_status = [shipper = shipper_.get()] { return shipper->Snapshot(); };
  }
  options.rig_description = ToRigDescription(config);
  options.white_reflectance = config.sample.white_reflectance;
  options.uncertainty = ReadingBudgetSettingsFrom(config);
  options.uncertainty_model = [](const adaptive::AdaptiveSpec& spec) {
    return adaptive::MakeInterpolatedModel(spec);
  };
  options.rig_name = RigName(config);
  if (Status adopted = store_->AdoptUnnamedSessions(options.rig_name); !adopted.ok()) {
    spdlog::critical("naming the rig of older sessions failed: {}", adopted.ToString());
    return adopted;
  }
  manager_ = std::make_unique<SessionManager>(store_, std::shared_ptr<Rig>(std::move(rig)),
                                              std::move(options));
  Result<std::vector<SessionId>> recovered = manager_->Recover();
  if (!recovered.ok()) {
    spdlog::critical("recovering interrupted sessions failed: {}", recovered.status().ToString());
    return recovered.status();
  }
  if (!recovered->empty()) {
    spdlog::warn("{} session(s) were interrupted by the previous run and are now paused",
                 recovered->size());
  }
  return Status::Ok();
}

RigBackEnd::~RigBackEnd() {
  if (shipper_ != nullptr) shipper_->Stop();
  if (manager_ != nullptr) manager_->RemoveReadingListener(cache_listener_);
}

BackEnd RigBackEnd::Served() {
  return BackEnd{"brdfd", catalogue_.get(), cache_.get(), port_.get(), {}};  // exports: Serving
}

void RigBackEnd::Shutdown(std::chrono::milliseconds timeout) {
  manager_->Shutdown(timeout);
  manager_->RemoveReadingListener(cache_listener_);
  spdlog::info("sessions paused and devices closed; stopping the server");
}

}  // namespace brdf::daemon
