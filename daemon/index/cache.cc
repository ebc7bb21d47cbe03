#include "daemon/index/cache.h"

#include <algorithm>
#include <optional>
#include <utility>

#include "core/plan/sample.h"
#include "daemon/index/build.h"
#include "daemon/index/samples.h"
#include "daemon/sessions/session_plan.h"

namespace brdf::daemon {
namespace {

// An index of a session, with the tick of its last query (least recently used first out).
struct KeptIndex {
  KeptIndex(IndexKey k, std::shared_ptr<const IndexSnapshot> i, std::uint64_t u)
      : key(std::move(k)), index(std::move(i)), used(u) {}
  IndexKey key;
  std::shared_ptr<const IndexSnapshot> index;
  mutable std::atomic<std::uint64_t> used;  // written by queries under Entry::state_mu shared
};

// A committed record waiting to be folded, roughly (for the cache's bound).
std::size_t RecordBytes(const storage::ReadingRecord& r) {
  return sizeof(r) + r.spectrum.size() * sizeof(double);
}

}  // namespace

struct IndexCache::Entry {
  // Serialises loads, folds and builds; guards everything below except the pending records,
  // bytes, announced_id and used. state_mu guards loaded, the published samples and indexes as
  // well: they are written with both held (build_mu first), so the query fast path (FreshHit)
  // reads them under state_mu shared alone, while a build goes on.
  std::mutex build_mu;
  mutable std::shared_mutex state_mu;

  bool loaded = false;                  // the first load from the store is done
  std::optional<IndexSamples> samples;  // set by the first load
  std::list<KeptIndex> indexes;

  // Records handed over by OnReading, in commit order, not folded yet.
  std::mutex pending_mu;
  std::vector<storage::ReadingRecord> pending;
  std::atomic<std::size_t> pending_bytes{0};

  std::atomic<std::size_t> bytes{0};          // sets and indexes (EntryBytes), at the last build
  std::atomic<std::int64_t> announced_id{0};  // highest reading id handed over (OnReading)
  std::atomic<std::uint64_t> used{0};         // IndexCache::tick_ of the last query
};

IndexCache::IndexCache(std::shared_ptr<storage::SessionReader> store, Options options,
                       PlanSource plans)
    : store_(std::move(store)), options_(options), plans_(std::move(plans)) {}

// --- Commit events ------------------------------------------------------------------------------

void IndexCache::OnReading(SessionId session, const storage::ReadingRecord& reading) {
  std::shared_ptr<Entry> entry;
  {
    std::shared_lock lock(mu_);
    auto it = entries_.find(session);
    if (it == entries_.end()) return;  // not cached: its first load reads everything anyway
    entry = it->second;
  }
  std::size_t waiting = 0;
  {
    std::lock_guard lock(entry->pending_mu);
    entry->pending.push_back(reading);
    waiting = entry->pending_bytes += RecordBytes(reading);
    // After the record is queued: whoever sees the id also finds the record.
    std::int64_t seen = entry->announced_id.load();
    while (seen < reading.id && !entry->announced_id.compare_exchange_weak(seen, reading.id)) {
    }
  }
  if (waiting > options_.max_bytes) {
    // Measured for long without a query: let the session go; its next query loads it afresh.
    std::unique_lock lock(mu_);
    auto it = entries_.find(session);
    if (it != entries_.end() && it->second == entry) {
      entries_.erase(it);
      ++stats_.evictions;
    }
  }
}

// --- Queries ------------------------------------------------------------------------------------

IndexCache::Stats IndexCache::stats() const {
  std::shared_lock lock(mu_);
  Stats s = stats_;
  s.hits += hits_.load();
  s.sessions = entries_.size();
  s.bytes = 0;
  for (const auto& [id, e] : entries_) s.bytes += e->bytes.load() + e->pending_bytes.load();
  return s;
}

std::vector<std::pair<SessionId, std::int64_t>> IndexCache::HeldThrough() const {
  std::vector<std::pair<SessionId, std::shared_ptr<Entry>>> entries;
  {
    std::shared_lock lock(mu_);
    entries.assign(entries_.begin(), entries_.end());
  }
  std::vector<std::pair<SessionId, std::int64_t>> out;
  for (const auto& [id, entry] : entries) {
    const std::int64_t announced = entry->announced_id.load();
    std::shared_lock state(entry->state_mu);
    if (!entry->loaded) continue;
    out.emplace_back(id, std::max(announced, entry->samples->published().through_id));
  }
  return out;
}

std::shared_ptr<const IndexSnapshot> IndexCache::FreshHit(SessionId session, Quantity quantity,
                                                          interp::Method method,
                                                          const interp::Options& options) {
  std::shared_ptr<Entry> entry;
  {
    std::shared_lock lock(mu_);
    auto it = entries_.find(session);
    if (it == entries_.end()) return nullptr;
    entry = it->second;
  }
  const std::uint64_t now = ++tick_;
  entry->used.store(now, std::memory_order_relaxed);
  // Read before the state: a reading announced from here on was committed after this query
  // began, so an index that misses it is still an answer "over every reading committed so far".
  const std::int64_t announced = entry->announced_id.load();
  const IndexKey key = MakeIndexKey(quantity, method, options);
  const int qi = static_cast<int>(quantity);
  std::shared_lock state(entry->state_mu);
  if (!entry->loaded) return nullptr;
  const IndexSamples::State& published = entry->samples->published();
  if (announced > published.through_id) return nullptr;
  for (const KeptIndex& kept : entry->indexes) {
    if (kept.key == key) {
      if (kept.index->samples != published.sets[qi]) return nullptr;  // stale: extend or rebuild
      kept.used.store(now, std::memory_order_relaxed);
      hits_.fetch_add(1, std::memory_order_relaxed);
      return kept.index;
    }
  }
  return nullptr;
}

Result<std::shared_ptr<const IndexSnapshot>> IndexCache::Get(SessionId session, Quantity quantity,
                                                             interp::Method method,
                                                             const interp::Options& options) {
  if (std::shared_ptr<const IndexSnapshot> hit = FreshHit(session, quantity, method, options)) {
    return hit;
  }
  std::shared_ptr<Entry> entry = Lookup(session);
  std::unique_lock build(entry->build_mu);
  Counts counts;
  if (!entry->loaded) {
    if (Status st = Load(*entry, session, &counts.read); !st.ok()) {
      build.unlock();
      Forget(session, entry);  // an entry that never loaded (unknown session, store error)
      return st;
    }
    counts.first_load = true;
  }
  counts.appended = Append(*entry, &counts.folded);
  {
    std::unique_lock lock(mu_);
    Count(counts);
  }

  const IndexKey key = MakeIndexKey(quantity, method, options);
  std::shared_ptr<const IndexSnapshot> stale;  // this key's index over fewer readings, if any
  if (std::shared_ptr<const IndexSnapshot> hit = FindIndex(*entry, key, &stale)) {
    hits_.fetch_add(1, std::memory_order_relaxed);
    return hit;
  }

  // Options that do not fit the session are the caller's mistake, not the data's.
  const IndexSamples& samples = *entry->samples;
  BRDF_RETURN_IF_ERROR(CheckIndexOptions(options, samples.dims(), session));
  const int qi = static_cast<int>(quantity);
  const IndexSamples::State& published = samples.published();
  BRDF_RETURN_IF_ERROR(CheckHasSamples(published.sets[qi].get(), quantity, published.skipped[qi],
                                       published.skipped_detail[qi], session));
  BRDF_ASSIGN_OR_RETURN(MadeIndex made,
                        MakeIndex(published.sets[qi], method, options, stale.get(), session));
  std::shared_ptr<const CalibrationSlot> calibration =
      CarriedCalibration(stale.get(), published.sets[qi]->size());
  stale.reset();

  auto snapshot = std::make_shared<IndexSnapshot>();
  snapshot->session = session;
  snapshot->quantity = quantity;
  snapshot->method = method;
  snapshot->options = options;
  snapshot->anisotropic = samples.anisotropic();
  snapshot->dims = samples.dims();
  snapshot->grid = samples.grid();
  snapshot->through_reading_id = published.through_id;
  snapshot->skipped = published.skipped[qi];
  snapshot->skipped_detail = published.skipped_detail[qi];
  snapshot->samples = published.sets[qi];
  if (quantity == Quantity::kBrdf) snapshot->budgets = published.brdf_budgets;
  snapshot->calibration = std::move(calibration);
  snapshot->interpolator =
      std::shared_ptr<const interp::Interpolator>(std::move(made.interpolator));
  Keep(*entry, key, snapshot);
  build.unlock();

  {
    std::unique_lock lock(mu_);
    ++(made.extended ? stats_.extends : stats_.builds);
    Evict(session);
  }
  return std::shared_ptr<const IndexSnapshot>(std::move(snapshot));
}

// --- The steps of Get
// -----------------------------------------------------------------------------

std::shared_ptr<IndexCache::Entry> IndexCache::Lookup(SessionId session) {
  std::shared_ptr<Entry> entry;
  {
    std::unique_lock lock(mu_);
    std::shared_ptr<Entry>& slot = entries_[session];
    if (!slot) slot = std::make_shared<Entry>();
    entry = slot;
  }
  entry->used.store(++tick_, std::memory_order_relaxed);
  return entry;
}

void IndexCache::Forget(SessionId session, const std::shared_ptr<Entry>& entry) {
  std::unique_lock lock(mu_);
  auto it = entries_.find(session);
  if (it != entries_.end() && it->second == entry) entries_.erase(it);
}

Status IndexCache::Load(Entry& entry, SessionId session, std::uint64_t* read) {
  BRDF_ASSIGN_OR_RETURN(storage::SessionRecord record, store_->GetSession(session));
  bool anisotropic = false;
  std::optional<Spectrum> white_spectrum;
  if (plans_) {
    BRDF_ASSIGN_OR_RETURN(std::shared_ptr<const SessionPlan> plan, plans_(session));
    anisotropic = plan->plan.anisotropic();
    white_spectrum = plan::WhiteReflectanceSpectrumOf(plan->plan);
  } else {
    BRDF_ASSIGN_OR_RETURN(SessionPlan plan, ParseSessionPlan(record));
    anisotropic = plan.plan.anisotropic();
    white_spectrum = plan::WhiteReflectanceSpectrumOf(plan.plan);
  }
  IndexSamples samples(anisotropic, record.white_reflectance.value_or(kWhiteStandardReflectance),
                       std::move(white_spectrum));
  std::int64_t through = 0;
  for (;;) {
    BRDF_ASSIGN_OR_RETURN(std::vector<storage::ReadingRecord> page,
                          store_->GetReadings(session, through, options_.page_size));
    *read += page.size();
    for (const storage::ReadingRecord& r : page) {
      through = std::max(through, r.id);
      samples.Fold(r);
    }
    if (static_cast<int>(page.size()) < options_.page_size) break;
  }
  std::unique_lock state(entry.state_mu);
  entry.samples.emplace(std::move(samples));
  entry.loaded = true;
  return Status::Ok();
}

bool IndexCache::Append(Entry& entry, std::uint64_t* folded) {
  std::vector<storage::ReadingRecord> handed;
  {
    std::lock_guard lock(entry.pending_mu);
    handed.swap(entry.pending);
    entry.pending_bytes = 0;
  }
  IndexSamples& samples = *entry.samples;
  for (const storage::ReadingRecord& r : handed) {
    if (samples.Fold(r)) ++*folded;
  }
  if (!samples.changed()) return false;
  std::unique_lock state(entry.state_mu);
  if (!samples.Publish()) return false;
  // Indexes over fewer readings are stale. Octant ones stay, to be extended on their next
  // query; the others are rebuilt then, so they need not be kept.
  const IndexSamples::State& published = samples.published();
  entry.indexes.remove_if([&](const KeptIndex& kept) {
    const IndexSnapshot& index = *kept.index;
    return index.method != interp::Method::kOctant &&
           index.samples != published.sets[static_cast<int>(index.quantity)];
  });
  return true;
}

std::shared_ptr<const IndexSnapshot> IndexCache::FindIndex(
    Entry& entry, const IndexKey& key, std::shared_ptr<const IndexSnapshot>* stale) {
  const IndexSamples::State& published = entry.samples->published();
  const auto& current = published.sets[static_cast<int>(key.quantity)];
  for (auto it = entry.indexes.begin(); it != entry.indexes.end(); ++it) {
    if (!(it->key == key)) continue;
    if (it->index->samples == current) {
      it->used.store(++tick_, std::memory_order_relaxed);
      return it->index;
    }
    *stale = it->index;
    std::unique_lock state(entry.state_mu);
    entry.indexes.erase(it);
    return nullptr;
  }
  return nullptr;
}

void IndexCache::Keep(Entry& entry, const IndexKey& key,
                      std::shared_ptr<const IndexSnapshot> index) {
  {
    std::unique_lock state(entry.state_mu);
    entry.indexes.emplace_back(key, std::move(index), ++tick_);
    while (entry.indexes.size() > std::max<std::size_t>(1, options_.max_indexes_per_session)) {
      // The least recently queried one (the one just made has the newest tick).
      entry.indexes.erase(std::min_element(
          entry.indexes.begin(), entry.indexes.end(),
          [](const KeptIndex& a, const KeptIndex& b) { return a.used.load() < b.used.load(); }));
    }
  }
  entry.bytes = EntryBytes(entry);
}

// --- Memory and counts
// ----------------------------------------------------------------------------

std::size_t IndexCache::EntryBytes(const Entry& entry) {
  std::size_t bytes = 0;
  for (const auto& set : entry.samples->published().sets) {
    if (set) bytes += SetBytes(*set);
  }
  bytes += entry.samples->published().brdf_budgets.bytes();
  for (const KeptIndex& kept : entry.indexes) bytes += kept.index->interpolator->HeapBytes();
  return bytes;
}

void IndexCache::Count(const Counts& counts) {
  stats_.readings_read += counts.read;
  stats_.readings_folded += counts.folded;
  if (!counts.appended) return;
  ++stats_.loads;
  if (!counts.first_load) ++stats_.appends;
}

void IndexCache::Evict(SessionId keep) {
  auto total = [this] {
    std::size_t sum = 0;
    for (const auto& [id, e] : entries_) sum += e->bytes.load() + e->pending_bytes.load();
    return sum;
  };
  while (entries_.size() > std::max<std::size_t>(1, options_.max_sessions) ||
         total() > options_.max_bytes) {
    // The least recently queried session other than `keep`.
    auto lru = entries_.end();
    for (auto it = entries_.begin(); it != entries_.end(); ++it) {
      if (it->first != keep &&
          (lru == entries_.end() || it->second->used.load() < lru->second->used.load())) {
        lru = it;
      }
    }
    if (lru == entries_.end()) break;
    entries_.erase(lru);
    ++stats_.evictions;
  }
}

IndexCache::Options IndexCacheOptionsFrom(const Config& config) {
  IndexCache::Options options;
  options.max_sessions = static_cast<std::size_t>(config.index.max_sessions);
  options.max_bytes = static_cast<std::size_t>(config.index.max_mb) << 20;
  return options;
}

}  // namespace brdf::daemon
