// CacheRefresher: keeps brdf-archive's index cache current without commit events. Every
// `interval` a thread asks the archive for readings above those each cached session holds
// (IndexCache::HeldThrough) and hands them over (IndexCache::OnReading), so a session still
// recording on its rig grows here as it is shipped.
#pragma once

#include <chrono>
#include <memory>
#include <thread>

#include "daemon/api/common.h"
#include "daemon/index/cache.h"
#include "storage/archive/reader.h"

namespace brdf::daemon {

class CacheRefresher {
 public:
  // Starts the thread. `cache` must outlive the refresher.
  CacheRefresher(std::shared_ptr<storage::ArchiveReader> archive, IndexCache& cache,
                 std::chrono::milliseconds interval);
  // Stops the thread (Stop).
  ~CacheRefresher();
  CacheRefresher(const CacheRefresher&) = delete;
  CacheRefresher& operator=(const CacheRefresher&) = delete;

  // Ends the thread, after the pass in progress. Idempotent.
  void Stop();

 private:
  void Run();
  // Brings one cached session up to date; false when the archive could not be read.
  bool Refresh(SessionId session, std::int64_t through, bool failing);

  std::shared_ptr<storage::ArchiveReader> archive_;
  IndexCache& cache_;
  std::chrono::milliseconds interval_;
  StopSignal stopping_;
  std::thread thread_;
};

}  // namespace brdf::daemon
