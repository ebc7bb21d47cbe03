#include "daemon/rpc/memory_budget.h"

#include <malloc.h>
#include <spdlog/spdlog.h>
#include <unistd.h>

#include <chrono>
#include <cstdio>
#include <string>

namespace brdf::daemon {
namespace {

constexpr std::uint64_t kMiB = 1024 * 1024;
// glibc's arenas (default 8 per core): a few are enough for brdfd's threads, which mostly wait.
constexpr int kArenas = 4;
constexpr std::chrono::seconds kTrimPeriod{1};

std::string Mb(std::uint64_t bytes) {
  return std::to_string((bytes + kMiB / 2) / kMiB) + " MB";
}

std::int64_t NowNs() {
  return std::chrono::duration_cast<std::chrono::nanoseconds>(
             std::chrono::steady_clock::now().time_since_epoch())
      .count();
}

}  // namespace

void ConfigureAllocator() {
  (void)::mallopt(M_ARENA_MAX, kArenas);
}

std::uint64_t ResidentBytes() {
  std::FILE* f = std::fopen("/proc/self/statm", "r");
  if (f == nullptr) return 0;
  unsigned long long size = 0, resident = 0;
  const int got = std::fscanf(f, "%llu %llu", &size, &resident);
  std::fclose(f);
  if (got != 2) return 0;
  return resident * static_cast<std::uint64_t>(::sysconf(_SC_PAGESIZE));
}

MemoryBudget::MemoryBudget(int budget_mb)
    : budget_(static_cast<std::uint64_t>(budget_mb < 1 ? 1 : budget_mb) * kMiB) {}

grpc::Status MemoryBudget::Reserve(std::string_view rpc, std::uint64_t bytes,
                                   std::unique_ptr<Reservation>* out) {
  const std::uint64_t resident = ResidentBytes();
  {
    MutexLock lock(mu_);
    if (reserved_ + bytes <= budget_ && resident <= budget_) {
      reserved_ += bytes;
      out->reset(new Reservation(this, bytes));
      return grpc::Status::OK;
    }
  }
  refused_.fetch_add(1);
  const std::string why =
      resident > budget_
          ? "brdfd already holds " + Mb(resident) + " (resident)"
          : "it needs about " + Mb(bytes) + " and the calls in flight hold " + Mb(reserved_bytes());
  return grpc::Status(grpc::StatusCode::RESOURCE_EXHAUSTED,
                      std::string(rpc) + ": brdfd's memory budget for heavy calls is " +
                          Mb(budget_) + " ([server] memory_budget_mb) and " + why +
                          "; try again when other exports and batches have ended, ask for less, "
                          "or raise memory_budget_mb");
}

std::uint64_t MemoryBudget::reserved_bytes() const {
  MutexLock lock(mu_);
  return reserved_;
}

void MemoryBudget::Release(std::uint64_t bytes) {
  {
    MutexLock lock(mu_);
    reserved_ -= bytes;
  }
  AskTrim();
}

void MemoryBudget::TrimIfDue() {
  const std::int64_t now = NowNs();
  if (!trim_wanted_.load() ||
      now - last_trim_ns_.load() <
          std::chrono::duration_cast<std::chrono::nanoseconds>(kTrimPeriod).count()) {
    return;
  }
  trim_wanted_.store(false);
  last_trim_ns_.store(now);
  (void)::malloc_trim(0);
  trims_.fetch_add(1);
}

}  // namespace brdf::daemon
