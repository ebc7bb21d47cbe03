// ArchiveBackEnd: what brdf-archive serves over one ArchiveReader: its sessions (catalogue.h) and
// the index cache Interpolation answers from, kept current as the rigs ship (refresher.h). No rig.
#pragma once

#include <chrono>
#include <memory>

#include "daemon/api/server.h"
#include "daemon/archive/catalogue.h"
#include "daemon/archive/refresher.h"
#include "daemon/index/cache.h"
#include "storage/archive/reader.h"

namespace brdf::daemon {

class ArchiveBackEnd {
 public:
  // `refresh`: how often cached sessions are brought up to date with the archive.
  explicit ArchiveBackEnd(std::shared_ptr<storage::ArchiveReader> archive,
                          std::chrono::milliseconds refresh = std::chrono::seconds(1),
                          IndexCache::Options cache = IndexCache::Options());
  ArchiveBackEnd(const ArchiveBackEnd&) = delete;
  ArchiveBackEnd& operator=(const ArchiveBackEnd&) = delete;

  // For the server: "brdf-archive", the archive's sessions, their indexes, no rig.
  BackEnd Served();
  IndexCache::Stats cache_stats() const { return cache_.stats(); }

  // Stops bringing cached sessions up to date (at shutdown; also the destructor's).
  void Stop() { refresher_.Stop(); }

 private:
  ArchiveCatalogue catalogue_;
  IndexCache cache_;
  CacheRefresher refresher_;  // after cache_, which it feeds
};

}  // namespace brdf::daemon
