#include "daemon/archive/refresher.h"

#include <spdlog/spdlog.h>

#include <utility>
#include <vector>

namespace brdf::daemon {
namespace {

// Readings fetched per archive page when a cached session is brought up to date.
constexpr int kRefreshPage = 512;

}  // namespace

CacheRefresher::CacheRefresher(std::shared_ptr<storage::ArchiveReader> archive, IndexCache& cache,
                               std::chrono::milliseconds interval)
    : archive_(std::move(archive)), cache_(cache), interval_(interval) {
  thread_ = std::thread([this] { Run(); });
}

CacheRefresher::~CacheRefresher() {
  Stop();
}

void CacheRefresher::Stop() {
  stopping_.Stop();
  if (thread_.joinable()) thread_.join();
}

void CacheRefresher::Run() {
  bool failing = false;
  while (!stopping_.WaitFor(interval_)) {
    for (const auto& [session, through] : cache_.HeldThrough()) {
      failing = !Refresh(session, through, failing);
    }
  }
}

bool CacheRefresher::Refresh(SessionId session, std::int64_t through, bool failing) {
  std::int64_t after = through;
  for (;;) {
    Result<std::vector<storage::ReadingRecord>> page =
        archive_->GetReadings(session, after, kRefreshPage);
    if (!page.ok()) {
      if (!failing) {
        spdlog::warn("bringing cached session {} up to date with the archive: {}", session,
                     page.status().ToString());
      }
      return false;
    }
    for (const storage::ReadingRecord& r : *page) {
      cache_.OnReading(session, r);
      after = r.id;
    }
    if (static_cast<int>(page->size()) < kRefreshPage) return true;
  }
}

}  // namespace brdf::daemon
