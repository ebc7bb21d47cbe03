// bench_index_memory: where a cached session's memory goes in the index cache (daemon/index),
// session by session of a brdfd database: its sample sets (one per quantity), the BRDF readings'
// uncertainty budgets, the octant BRDF index, each as the cache accounts it (SetBytes,
// BudgetList::bytes, Interpolator::HeapBytes) and as the heap holds it (glibc's mallinfo2, in use
// before and after; one thread, so the difference is what the step kept). Then the whole entry
// through an IndexCache of one session (stats().bytes) against the heap.
//
// Usage: bench_index_memory --database brdfd.db (a copy: it is opened as brdfd would open it)
// Prints one line per session.
#include <malloc.h>

#include <CLI/CLI.hpp>
#include <cstdio>
#include <memory>
#include <string>

#include "core/interp/interpolator.h"
#include "daemon/index/build.h"
#include "daemon/index/cache.h"
#include "daemon/index/samples.h"
#include "daemon/sessions/session_plan.h"
#include "storage/session_store.h"

namespace {

using brdf::Quantity;
using brdf::daemon::IndexCache;
using brdf::daemon::IndexSamples;

double HeapMb() {
  malloc_trim(0);
  return static_cast<double>(mallinfo2().uordblks) / (1 << 20);
}

double Mb(std::size_t bytes) {
  return static_cast<double>(bytes) / (1 << 20);
}

// The session's samples and budgets folded as the cache's first load folds them, and its octant
// BRDF index; prints accounted and heap figures. False when the session cannot be read.
bool Probe(const std::shared_ptr<brdf::storage::SessionStore>& store, std::int64_t session) {
  brdf::Result<brdf::storage::SessionRecord> record = store->GetSession(session);
  if (!record.ok()) return false;
  brdf::Result<brdf::daemon::SessionPlan> plan = brdf::daemon::ParseSessionPlan(*record);
  if (!plan.ok()) return false;
  const double heap0 = HeapMb();
  auto samples = std::make_unique<IndexSamples>(
      plan->plan.anisotropic(), record->white_reflectance.value_or(0.99), std::nullopt);
  std::int64_t through = 0;
  for (;;) {
    brdf::Result<std::vector<brdf::storage::ReadingRecord>> page =
        store->GetReadings(session, through, 512);
    if (!page.ok()) return false;
    for (const auto& r : *page) {
      through = std::max(through, r.id);
      samples->Fold(r);
    }
    if (page->size() < 512) break;
  }
  samples->Publish();
  const double heap1 = HeapMb();
  const IndexSamples::State& state = samples->published();
  std::size_t sets = 0;
  for (const auto& set : state.sets) {
    if (set) sets += brdf::daemon::SetBytes(*set);
  }
  const auto& brdf_set = state.sets[static_cast<int>(Quantity::kBrdf)];
  if (!brdf_set) return false;
  auto index = brdf::interp::MakeInterpolator(brdf::interp::Method::kOctant, brdf_set, {});
  if (!index.ok()) return false;
  const double heap2 = HeapMb();
  std::printf(
      "session=%lld readings=%zu bands=%d sets_mb=%.1f budgets_mb=%.1f "
      "sets_and_budgets_heap_mb=%.1f "
      "octant_index_mb=%.1f octant_index_heap_mb=%.1f",
      static_cast<long long>(session), brdf_set->size(), brdf_set->bands(), Mb(sets),
      Mb(state.brdf_budgets.bytes()), heap1 - heap0, Mb((*index)->HeapBytes()), heap2 - heap1);
  index->reset();
  samples.reset();

  // The whole entry as the cache holds it (its own accounting), against the heap.
  const double heap3 = HeapMb();
  IndexCache cache(store, IndexCache::Options{.max_sessions = 1});
  if (!cache.Get(session, Quantity::kBrdf, brdf::interp::Method::kOctant, {}).ok()) return false;
  std::printf(" entry_mb=%.1f entry_heap_mb=%.1f\n", Mb(cache.stats().bytes), HeapMb() - heap3);
  return true;
}

}  // namespace

int main(int argc, char** argv) {
  CLI::App app{"Where a cached session's memory goes in brdfd's index cache"};
  std::string database;
  app.add_option("--database", database, "a copy of a brdfd database")->required();
  CLI11_PARSE(app, argc, argv);
  brdf::Result<std::unique_ptr<brdf::storage::SessionStore>> opened =
      brdf::storage::SessionStore::Open(database);
  if (!opened.ok()) {
    std::fprintf(stderr, "cannot open %s: %s\n", database.c_str(),
                 opened.status().ToString().c_str());
    return 1;
  }
  std::shared_ptr<brdf::storage::SessionStore> store = std::move(*opened);
  for (std::int64_t session = 1; Probe(store, session); ++session) {
  }
  return 0;
}
