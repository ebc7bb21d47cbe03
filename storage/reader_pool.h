// A few extra connections to one database file, for reading. In WAL mode a reader sees the last
// committed snapshot without waiting for (or delaying) the single writer, so a client streaming
// readings or asking for a session's status never stalls behind a measurement's fsync.
// Connections are opened read-only (a read path cannot write by mistake) and on demand; up to
// `max_idle` are kept open between uses.
#pragma once

#include <cstddef>
#include <memory>
#include <string>
#include <vector>

#include "core/mutex.h"
#include "core/status.h"
#include "storage/sqlite.h"

namespace brdf::storage {

class ReaderPool {
 public:
  // A connection borrowed from the pool; returned when the Lease is destroyed. Must not outlive
  // the pool.
  class Lease {
   public:
    Lease(Lease&& other) noexcept : pool_(other.pool_), db_(std::move(other.db_)) {}
    Lease& operator=(Lease&&) = delete;
    ~Lease();
    Database& operator*() const { return *db_; }
    Database* operator->() const { return db_.get(); }

   private:
    friend class ReaderPool;
    Lease(ReaderPool* pool, std::unique_ptr<Database> db) : pool_(pool), db_(std::move(db)) {}
    ReaderPool* pool_;
    std::unique_ptr<Database> db_;
  };

  ReaderPool(std::string path, OpenOptions options, std::size_t max_idle = 4);

  // An idle connection, or a newly opened one.
  Result<Lease> Acquire();

 private:
  void Return(std::unique_ptr<Database> db);

  std::string path_;
  OpenOptions options_;
  std::size_t max_idle_;
  Mutex mu_;
  std::vector<std::unique_ptr<Database>> idle_ GUARDED_BY(mu_);
};

}  // namespace brdf::storage
