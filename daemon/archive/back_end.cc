#include "daemon/archive/back_end.h"

#include <utility>

namespace brdf::daemon {

ArchiveBackEnd::ArchiveBackEnd(std::shared_ptr<storage::ArchiveReader> archive,
                               std::chrono::milliseconds refresh, IndexCache::Options cache)
    : catalogue_(archive), cache_(archive, cache), refresher_(archive, cache_, refresh) {}

BackEnd ArchiveBackEnd::Served() {
  return BackEnd{"brdf-archive", &catalogue_, &cache_, nullptr, {}};  // exports: Serving
}

}  // namespace brdf::daemon
