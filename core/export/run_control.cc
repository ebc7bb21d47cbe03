#include "core/export/run_control.h"

#include <algorithm>
#include <atomic>
#include <string>
#include <thread>
#include <utility>
#include <vector>

namespace brdf::exports {

unsigned ResolveThreads(unsigned requested) {
  if (requested > 0) return requested;
  return std::max(1u, std::thread::hardware_concurrency());
}

ProgressReporter::ProgressReporter(ProgressFn fn, std::size_t total_units)
    : fn_(std::move(fn)),
      total_(total_units),
      step_(std::max<std::size_t>(1, total_units / 1000)) {}

void ProgressReporter::Report(std::size_t units_done) {
  if (!fn_ || finished_ || total_ == 0) return;
  units_done = std::min(units_done, total_);
  if (units_done < last_ + step_ || units_done >= total_) return;  // 1.0 is Finish's to report
  last_ = units_done;
  fn_(static_cast<double>(units_done) / static_cast<double>(total_));
}

void ProgressReporter::Finish() {
  if (finished_) return;
  finished_ = true;
  if (fn_) fn_(1.0);
}

namespace {

// Small enough for a prompt cancel and a smooth progress line (a cell costs microseconds to tens
// of microseconds), large enough that the shared counter is not contended.
constexpr std::size_t kChunk = 256;

}  // namespace

Status ParallelFor(std::size_t count, unsigned threads, const CallContext& ctx,
                   ProgressReporter* progress, std::size_t progress_base, const char* what,
                   const std::function<void(std::size_t begin, std::size_t end)>& body) {
  return ParallelForChunks(count, kChunk, threads, ctx, progress, progress_base, what, body);
}

Status ParallelForChunks(std::size_t count, std::size_t chunk, unsigned threads,
                         const CallContext& ctx, ProgressReporter* progress,
                         std::size_t progress_base, const char* what,
                         const std::function<void(std::size_t begin, std::size_t end)>& body) {
  chunk = std::max<std::size_t>(1, chunk);
  std::atomic<std::size_t> next{0};
  std::atomic<std::size_t> done{0};
  std::atomic<bool> stop{false};
  auto should_stop = [&] {
    if (stop.load(std::memory_order_relaxed)) return true;
    if (ctx.cancelled() || ctx.expired()) {
      stop.store(true, std::memory_order_relaxed);
      return true;
    }
    return false;
  };
  auto work = [&](bool report) {
    for (;;) {
      if (should_stop()) return;
      const std::size_t begin = next.fetch_add(chunk, std::memory_order_relaxed);
      if (begin >= count) return;
      const std::size_t end = std::min(count, begin + chunk);
      body(begin, end);
      const std::size_t now = done.fetch_add(end - begin, std::memory_order_relaxed) + end - begin;
      if (report && progress != nullptr) progress->Report(progress_base + now);
    }
  };

  const unsigned n =
      std::max(1u, std::min<unsigned>(threads, static_cast<unsigned>((count + chunk - 1) / chunk)));
  std::vector<std::thread> workers;
  workers.reserve(n - 1);
  for (unsigned t = 1; t < n; ++t) workers.emplace_back(work, false);
  work(true);
  for (std::thread& w : workers) w.join();

  if (stop.load() && done.load() < count) {
    const std::string where = std::string(what) + " stopped after " + std::to_string(done.load()) +
                              " of " + std::to_string(count) + " cells";
    if (ctx.cancelled()) return Cancelled(where + ": " + ctx.cancel().reason());
    return Timeout(where + ": the deadline passed; allow more time or export a coarser grid");
  }
  return Status::Ok();
}

}  // namespace brdf::exports
