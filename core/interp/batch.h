// Evaluating many queries at once on several threads. Queries are cut into chunks; the threads
// of a pool take chunks as they finish the previous one; every answer is written at its query's
// position, so the output is the same, bit for bit, whatever the thread count or the scheduling.
// Long batches (rendering-scale grids) can report progress and be cancelled between chunks.
// Pure: no I/O.
#pragma once

#include <atomic>
#include <condition_variable>
#include <cstddef>
#include <functional>
#include <mutex>
#include <span>
#include <thread>
#include <vector>

#include "core/call_context.h"
#include "core/interp/interpolator.h"
#include "core/status.h"

namespace brdf::interp {

// A fixed set of threads for batches, started once and reused (starting threads per batch costs
// more than a small batch). The calling thread works too: a pool of N threads starts N − 1.
class BatchPool {
 public:
  // threads < 1 counts as 1 (everything on the calling thread).
  explicit BatchPool(int threads);
  ~BatchPool();  // stops and joins the workers
  BatchPool(const BatchPool&) = delete;
  BatchPool& operator=(const BatchPool&) = delete;

  int threads() const { return static_cast<int>(workers_.size()) + 1; }

  // Calls task(i) once for every i in [0, count), spread over the pool's threads, and returns
  // when every call has returned. Tasks must not throw. Calls from several threads at once take
  // turns (one job at a time per pool).
  void ParallelFor(std::size_t count, const std::function<void(std::size_t)>& task);

 private:
  void WorkerLoop();
  void RunTasks();

  std::vector<std::jthread> workers_;
  std::mutex job_mutex_;  // one ParallelFor at a time
  std::mutex mu_;
  std::condition_variable wake_;  // workers: a new job (or stop)
  std::condition_variable done_;  // caller: every worker has left the job
  std::uint64_t generation_ = 0;  // guarded by mu_
  bool stop_ = false;             // guarded by mu_
  int busy_ = 0;                  // workers still in the current job; guarded by mu_
  const std::function<void(std::size_t)>* task_ = nullptr;
  std::size_t count_ = 0;
  std::atomic<std::size_t> next_{0};
};

struct BatchOptions {
  // Threads when no pool is given (a pool is made for the call). Ignored when `pool` is set.
  int threads = 1;
  BatchPool* pool = nullptr;
  // Queries per chunk: the unit of work sharing, progress and cancellation, and one SpectraAt
  // call: large enough for the octant method to sort a chunk by cell (a quarter of a query per
  // cell: about 2,000 queries on the rig grid, 6,000 on 50,000 points; octant/octant.h).
  std::size_t chunk = 16384;
  // Checked before each chunk: once cancelled or past its deadline, no new chunk starts and the
  // batch returns kCancelled or kTimeout (the outputs then hold only some answers).
  const CallContext* context = nullptr;
  // Called after each chunk with the number of queries answered so far (increasing) and the
  // total; calls never overlap. Keep it cheap.
  std::function<void(std::size_t done, std::size_t total)> progress;
};

// Evaluates queries.size() / dims() queries (row-major, dims() coordinates each) and returns the
// answers in query order, identical to calling Evaluate on each. Errors (kInvalidArgument):
// queries.size() not a multiple of dims(); kCancelled / kTimeout from options.context.
Result<std::vector<Interpolation>> EvaluateBatch(const Interpolator& interpolator,
                                                 std::span<const double> queries,
                                                 const BatchOptions& options = {});

// The fast path for grids and rendering: statuses and spectra only (EvaluateSpectrum), no
// provenance and no allocation per query. For n queries, statuses.size() == n and spectra.size()
// == n × bands, row i holding query i's spectrum; the rows of queries that are not kOk are set to
// NaN. Errors (kInvalidArgument): sizes that do not match; kCancelled / kTimeout as above.
Status EvaluateSpectraBatch(const Interpolator& interpolator, std::span<const double> queries,
                            std::span<InterpStatus> statuses, std::span<double> spectra,
                            const BatchOptions& options = {});

}  // namespace brdf::interp
