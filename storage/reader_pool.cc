#include "storage/reader_pool.h"

#include <utility>

namespace brdf::storage {

ReaderPool::Lease::~Lease() {
  if (db_ != nullptr) pool_->Return(std::move(db_));
}

ReaderPool::ReaderPool(std::string path, OpenOptions options, std::size_t max_idle)
    : path_(std::move(path)), options_(options), max_idle_(max_idle) {
  options_.read_only = true;
  options_.create = false;
}

Result<ReaderPool::Lease> ReaderPool::Acquire() {
  {
    MutexLock lock(mu_);
    if (!idle_.empty()) {
      std::unique_ptr<Database> db = std::move(idle_.back());
      idle_.pop_back();
      return Lease(this, std::move(db));
    }
  }
  Result<std::unique_ptr<Database>> db = Database::Open(path_, options_);
  if (!db.ok()) return db.status().WithContext("opening a reader connection");
  return Lease(this, std::move(db).value());
}

void ReaderPool::Return(std::unique_ptr<Database> db) {
  // A connection left inside a transaction (a bug) would pin an old snapshot; drop it instead.
  if (db->in_transaction()) return;
  MutexLock lock(mu_);
  if (idle_.size() < max_idle_) idle_.push_back(std::move(db));
}

}  // namespace brdf::storage
