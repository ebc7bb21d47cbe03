// brdfd's memory budget for the heavy calls (issue 40): InterpolateBatch, Export and
// RenderAppearance, the calls whose memory grows with what they are asked, reserve what they will
// hold at most before they start ([server] memory_budget_mb in the configuration, config.h). A
// call whose reservation would take the sum of those in flight beyond the budget, or that arrives
// while brdfd's resident memory (VmRSS) is already beyond it, is refused with RESOURCE_EXHAUSTED
// naming the budget and the key to raise; the calls in flight are never cut short. The control
// plane, Interpolate and the light streams (WatchSession, StreamReadings) reserve nothing.
//
// Memory back to the system: glibc keeps what a thread freed in its arena; after the heavy calls
// end, the registry's watchdog asks for it back (TrimIfDue: malloc_trim(0), at most once a second,
// off the calls' threads). ConfigureAllocator, at start-up, caps glibc's arenas (M_ARENA_MAX 4):
// a thousand stream threads otherwise spread their garbage over 16 arenas per two cores' 8.
#pragma once

#include <grpcpp/support/status.h>

#include <atomic>
#include <cstdint>
#include <memory>
#include <string_view>

#include "core/mutex.h"

namespace brdf::daemon {

// mallopt at start-up (before the threads): fewer arenas, so freed memory is reused and trimmed
// rather than kept per thread. Process-wide; idempotent.
void ConfigureAllocator();

// The process's resident memory now (VmRSS, from /proc/self/statm), bytes; 0 when unknown.
std::uint64_t ResidentBytes();

class MemoryBudget {
 public:
  // `budget_mb` ≥ 1.
  explicit MemoryBudget(int budget_mb);
  MemoryBudget(const MemoryBudget&) = delete;
  MemoryBudget& operator=(const MemoryBudget&) = delete;

  // What one call holds; given back (and a trim asked for) by its destructor.
  class Reservation {
   public:
    Reservation(MemoryBudget* budget, std::uint64_t bytes) : budget_(budget), bytes_(bytes) {}
    ~Reservation() { budget_->Release(bytes_); }
    Reservation(const Reservation&) = delete;
    Reservation& operator=(const Reservation&) = delete;
    std::uint64_t bytes() const { return bytes_; }

   private:
    MemoryBudget* budget_;
    std::uint64_t bytes_;
  };

  // Reserves `bytes` for a call of `rpc`: OK, or RESOURCE_EXHAUSTED naming the budget, what is
  // reserved (or resident) and [server] memory_budget_mb.
  grpc::Status Reserve(std::string_view rpc, std::uint64_t bytes,
                       std::unique_ptr<Reservation>* out);

  // Asks for a trim: a call ended (heavy or not) and freed what it held.
  void AskTrim() { trim_wanted_.store(true); }
  // malloc_trim(0) when a call ended since the last trim and the last was ≥ 1 s ago. For
  // a background thread (the stream registry's watchdog).
  void TrimIfDue();

  std::uint64_t budget_bytes() const { return budget_; }
  std::uint64_t reserved_bytes() const;
  std::uint64_t refused() const { return refused_.load(); }
  std::uint64_t trims() const { return trims_.load(); }

 private:
  void Release(std::uint64_t bytes);

  const std::uint64_t budget_;
  mutable Mutex mu_;
  std::uint64_t reserved_ GUARDED_BY(mu_) = 0;
  std::atomic<bool> trim_wanted_{false};
  std::atomic<std::int64_t> last_trim_ns_{0};
  std::atomic<std::uint64_t> refused_{0};
  std::atomic<std::uint64_t> trims_{0};
};

}  // namespace brdf::daemon
