#include "daemon/api/shared_extras.h"

#include <iterator>
#include <utility>

namespace brdf::daemon {

std::shared_ptr<const ReadingExtras> SharedReadingExtras::Get(
    std::int64_t session, const std::function<ReadingExtras()>& read) {
  {
    MutexLock lock(mu_);
    auto it = held_.find(session);
    if (it != held_.end()) {
      if (std::shared_ptr<const ReadingExtras> held = it->second.lock()) return held;
    }
    // Forget the copies no stream holds any more.
    for (auto at = held_.begin(); at != held_.end();) {
      at = at->second.expired() ? held_.erase(at) : std::next(at);
    }
  }
  // Read outside the lock (a store query); two streams starting together may both read, and the
  // later one's copy is the one kept.
  auto fresh = std::make_shared<const ReadingExtras>(read());
  MutexLock lock(mu_);
  held_[session] = fresh;
  return fresh;
}

}  // namespace brdf::daemon
