// The step labels and averaging StreamReadings puts on each reading (ReadingExtras), shared by the
// streams of the same session (issue 40). A session's labels are fixed at submission; each stream
// read them once and kept its own copy, a map of one label per step: 300 followers of a session
// of ~1,600 steps held ~35 MB of the same labels (heaptrack, bench/daemon/control_plane.sh). Get()
// hands out the copy a stream of the session already holds, else reads it; copies are kept only
// while a stream holds them (weak references): nothing stays once the streams end.
#pragma once

#include <cstdint>
#include <functional>
#include <map>
#include <memory>

#include "core/mutex.h"
#include "daemon/wire/reading.h"

namespace brdf::daemon {

class SharedReadingExtras {
 public:
  // The extras of `session`: the copy held by another stream, else `read()`'s, then shared.
  std::shared_ptr<const ReadingExtras> Get(std::int64_t session,
                                           const std::function<ReadingExtras()>& read);

 private:
  Mutex mu_;
  std::map<std::int64_t, std::weak_ptr<const ReadingExtras>> held_ GUARDED_BY(mu_);
};

}  // namespace brdf::daemon
