#include "core/interp/batch.h"

#include <algorithm>
#include <atomic>
#include <limits>
#include <memory>
#include <optional>
#include <string>

namespace brdf::interp {

BatchPool::BatchPool(int threads) {
  for (int i = 1; i < threads; ++i) workers_.emplace_back([this] { WorkerLoop(); });
}

BatchPool::~BatchPool() {
  {
    std::lock_guard lock(mu_);
    stop_ = true;
  }
  wake_.notify_all();
  workers_.clear();  // joins
}

void BatchPool::RunTasks() {
  for (std::size_t i = next_.fetch_add(1, std::memory_order_relaxed); i < count_;
       i = next_.fetch_add(1, std::memory_order_relaxed)) {
    (*task_)(i);
  }
}

void BatchPool::WorkerLoop() {
  std::uint64_t seen = 0;
  for (;;) {
    {
      std::unique_lock lock(mu_);
      wake_.wait(lock, [&] { return stop_ || generation_ != seen; });
      if (stop_) return;
      seen = generation_;
    }
    RunTasks();
    {
      std::lock_guard lock(mu_);
      if (--busy_ == 0) done_.notify_one();
    }
  }
}

void BatchPool::ParallelFor(std::size_t count, const std::function<void(std::size_t)>& task) {
  if (count == 0) return;
  if (workers_.empty() || count == 1) {
    for (std::size_t i = 0; i < count; ++i) task(i);
    return;
  }
  std::lock_guard job(job_mutex_);
  {
    std::lock_guard lock(mu_);
    task_ = &task;
    count_ = count;
    next_.store(0, std::memory_order_relaxed);
    busy_ = static_cast<int>(workers_.size());
    ++generation_;
  }
  wake_.notify_all();
  RunTasks();
  std::unique_lock lock(mu_);
  done_.wait(lock, [&] { return busy_ == 0; });
  task_ = nullptr;
}

namespace {

// Runs `answer(first, last)` over chunks of [0, n) on the options' pool (or a pool made here),
// with progress and cancellation between chunks.
Status RunChunks(std::size_t n, const BatchOptions& options,
                 const std::function<void(std::size_t, std::size_t)>& answer) {
  const std::size_t chunk = std::max<std::size_t>(1, options.chunk);
  const std::size_t chunks = (n + chunk - 1) / chunk;
  std::optional<BatchPool> own;
  BatchPool* pool = options.pool;
  if (pool == nullptr) {
    const auto threads = static_cast<std::size_t>(std::max(1, options.threads));
    own.emplace(static_cast<int>(std::min(threads, std::max<std::size_t>(1, chunks))));
    pool = &*own;
  }
  std::atomic<bool> stopped{false};
  std::mutex progress_mu;
  std::size_t done = 0;  // guarded by progress_mu
  const CallContext* context = options.context;
  pool->ParallelFor(chunks, [&](std::size_t c) {
    if (stopped.load(std::memory_order_relaxed)) return;
    if (context != nullptr && (context->cancelled() || context->expired())) {
      stopped.store(true, std::memory_order_relaxed);
      return;
    }
    const std::size_t first = c * chunk;
    const std::size_t last = std::min(n, first + chunk);
    answer(first, last);
    std::lock_guard lock(progress_mu);
    done += last - first;
    if (options.progress) options.progress(done, n);
  });
  if (!stopped.load()) return Status::Ok();
  std::size_t answered;
  {
    std::lock_guard lock(progress_mu);
    answered = done;
  }
  const std::string where = "batch interpolation of " + std::to_string(n) + " queries (" +
                            std::to_string(answered) + " answered)";
  if (context->cancelled()) {
    return Cancelled(where + " cancelled (" + context->cancel().reason() +
                     "); the outputs are incomplete: run the batch again to get every answer");
  }
  return Timeout(where +
                 " passed its deadline before every chunk started; the outputs are incomplete: "
                 "allow more time, use more threads, or split the batch");
}

Status CheckQueries(const Interpolator& interpolator, std::span<const double> queries,
                    const char* what) {
  const auto d = static_cast<std::size_t>(interpolator.dims());
  if (d == 0 || queries.size() % d != 0) {
    return InvalidArgument(std::string(what) + ": " + std::to_string(queries.size()) +
                           " query coordinates is not a multiple of the samples' " +
                           std::to_string(d) + " coordinates per query");
  }
  return Status::Ok();
}

}  // namespace

Result<std::vector<Interpolation>> EvaluateBatch(const Interpolator& interpolator,
                                                 std::span<const double> queries,
                                                 const BatchOptions& options) {
  BRDF_RETURN_IF_ERROR(CheckQueries(interpolator, queries, "EvaluateBatch"));
  const auto d = static_cast<std::size_t>(interpolator.dims());
  const std::size_t n = queries.size() / d;
  std::vector<Interpolation> out(n);
  BRDF_RETURN_IF_ERROR(RunChunks(n, options, [&](std::size_t first, std::size_t last) {
    for (std::size_t i = first; i < last; ++i) {
      out[i] = interpolator.Evaluate(queries.subspan(i * d, d));
    }
  }));
  return out;
}

Status EvaluateSpectraBatch(const Interpolator& interpolator, std::span<const double> queries,
                            std::span<InterpStatus> statuses, std::span<double> spectra,
                            const BatchOptions& options) {
  BRDF_RETURN_IF_ERROR(CheckQueries(interpolator, queries, "EvaluateSpectraBatch"));
  const auto d = static_cast<std::size_t>(interpolator.dims());
  const std::size_t n = queries.size() / d;
  if (statuses.size() != n) {
    return InvalidArgument("EvaluateSpectraBatch: " + std::to_string(n) + " queries but room for " +
                           std::to_string(statuses.size()) + " statuses; give one per query");
  }
  if (n == 0) return Status::Ok();
  if (spectra.size() % n != 0 || spectra.empty()) {
    return InvalidArgument("EvaluateSpectraBatch: " + std::to_string(spectra.size()) +
                           " spectral values is not " + std::to_string(n) +
                           " queries × the samples' bands; give n × bands values");
  }
  const std::size_t bands = spectra.size() / n;
  return RunChunks(n, options, [&](std::size_t first, std::size_t last) {
    interpolator.SpectraAt(queries.subspan(first * d, (last - first) * d),
                           statuses.subspan(first, last - first),
                           spectra.subspan(first * bands, (last - first) * bands));
  });
}

}  // namespace brdf::interp
