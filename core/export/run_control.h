// How a long export runs: on how many threads, how it reports progress, how it is stopped. A
// gRPC handler streams the progress callback's fractions to its client and cancels the
// CallContext's token when the client goes away; brdf-export draws a progress line.
//
// Results never depend on the thread count: every cell is computed on its own and written to its
// own slot, so a run on 8 threads is bit-identical to a run on 1.
#pragma once

#include <cstddef>
#include <functional>

#include "core/call_context.h"
#include "core/status.h"

namespace brdf::exports {

// Receives the fraction of the work done, in [0, 1].
using ProgressFn = std::function<void(double fraction)>;

struct RunControl {
  // Threads that compute cells (the calling thread is one of them); 0 = one per hardware thread.
  unsigned threads = 1;
  // Called on the calling thread only, never concurrently, with fractions that never decrease:
  // about every 1/1000 of the work or after each batch of cells the interpolator answers at once
  // (grids: after each θi slice the sink took; MERL: 1/22 of the table), whichever is coarser,
  // and exactly once with 1.0 when the work is complete (not after a cancellation). May be empty.
  ProgressFn progress;
};

// The thread count RunControl::threads asks for (0 → hardware threads, at least 1).
unsigned ResolveThreads(unsigned requested);

// Turns units of work done into throttled progress calls. Used on the calling thread only.
class ProgressReporter {
 public:
  ProgressReporter(ProgressFn fn, std::size_t total_units);
  // `units_done` of the total are done; reports when it moved by ≥ 1/1000 since the last report.
  void Report(std::size_t units_done);
  // Reports 1.0 (once).
  void Finish();

 private:
  ProgressFn fn_;
  std::size_t total_;
  std::size_t step_;
  std::size_t last_ = 0;
  bool finished_ = false;
};

// Calls body(begin, end) on consecutive chunks of [0, count) from `threads` threads (the calling
// thread included) and returns when all are done. Before each chunk the workers check `ctx`: once
// it is cancelled or past its deadline no new chunk starts, and the call returns kCancelled or
// kTimeout (saying how many of `count` were done) after the running chunks finish. `progress`
// (may be null) is told progress_base + units done, from the calling thread. `what` names the
// work in messages ("MERL table"). body must only write what belongs to its own indices.
Status ParallelFor(std::size_t count, unsigned threads, const CallContext& ctx,
                   ProgressReporter* progress, std::size_t progress_base, const char* what,
                   const std::function<void(std::size_t begin, std::size_t end)>& body);

// ParallelFor with chunks of `chunk` indices (at least 1) instead of the default 256: for bodies
// that answer a chunk as one batch (SpectrumSource::Spectra), which needs thousands of cells to
// sort them by interpolation cell. Progress and cancellation then come once per chunk.
Status ParallelForChunks(std::size_t count, std::size_t chunk, unsigned threads,
                         const CallContext& ctx, ProgressReporter* progress,
                         std::size_t progress_base, const char* what,
                         const std::function<void(std::size_t begin, std::size_t end)>& body);

}  // namespace brdf::exports
