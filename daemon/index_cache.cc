#include "daemon/index_cache.h"

#include <algorithm>
#include <array>
#include <atomic>
#include <cmath>
#include <optional>
#include <span>
#include <tuple>
#include <utility>

#include "core/geometry.h"
#include "core/interp/octant.h"
#include "core/plan/plan_json.h"
#include "core/spectrum.h"

namespace brdf::daemon {

const char* QuantityName(Quantity q) {
  switch (q) {
    case Quantity::kRadiance:
      return "radiance";
    case Quantity::kReflectance:
      return "reflectance";
    case Quantity::kBrdf:
      return "brdf";
  }
  return "unknown";
}

namespace {

// What identifies an index within a session.
struct IndexKey {
  Quantity quantity;
  interp::Method method;
  std::vector<double> axis_scale;  // normalised: empty when all 1
  bool mirror_phi;
  bool reciprocity;
  bool operator==(const IndexKey& o) const {
    return std::tie(quantity, method, axis_scale, mirror_phi, reciprocity) ==
           std::tie(o.quantity, o.method, o.axis_scale, o.mirror_phi, o.reciprocity);
  }
};

IndexKey MakeKey(Quantity quantity, interp::Method method, const interp::Options& options) {
  IndexKey key{quantity, method, options.axis_scale, options.mirror_phi, options.reciprocity};
  if (std::all_of(key.axis_scale.begin(), key.axis_scale.end(), [](double s) { return s == 1; })) {
    key.axis_scale.clear();
  }
  return key;
}

struct Reference {
  std::vector<double> spectrum;
  WavelengthGrid grid;
  double theta_i = 0;  // incidence at which the white was read (θi,ref)
};

std::string ReadingName(const storage::ReadingRecord& r) {
  return "reading " + std::to_string(r.id) + " (step " + std::to_string(r.step_index) + ")";
}

// Samples of one set, the memory they take (roughly; for the cache's bound).
std::size_t SetBytes(const interp::SampleSet& set) {
  return set.size() * (static_cast<std::size_t>(set.dims() + set.bands()) * sizeof(double) +
                       sizeof(std::int64_t));
}

// An index over a set holds the (possibly augmented, up to 4×) coordinates and its search
// structure; 8 doubles per coordinate is a generous estimate for every method.
std::size_t IndexBytes(const interp::SampleSet& set) {
  return set.size() * static_cast<std::size_t>(set.dims()) * sizeof(double) * 8;
}

// An index of a session, with the tick of its last query (least recently used first out).
struct CachedIndex {
  CachedIndex(IndexKey k, std::shared_ptr<const IndexSnapshot> i, std::uint64_t u)
      : key(std::move(k)), index(std::move(i)), used(u) {}
  IndexKey key;
  std::shared_ptr<const IndexSnapshot> index;
  mutable std::atomic<std::uint64_t> used;  // written by queries under Entry::state_mu shared
};

}  // namespace

struct IndexCache::Entry {
  // Serialises store reads and builds; guards everything below except announced_id, bytes and
  // used. state_mu guards synced, through_id, sets and indexes as well: they are written with
  // both held (build_mu first), so the query fast path (FreshHit) reads them under state_mu
  // shared alone, while a build goes on.
  std::mutex build_mu;
  mutable std::shared_mutex state_mu;

  bool loaded = false;  // session record read (plan kind, ρw)
  bool anisotropic = false;
  double white_reflectance = kWhiteStandardReflectance;
  std::optional<WavelengthGrid> grid;  // of the first sample reading: the session's grid
  std::int64_t through_id = 0;         // readings read from the store up to this id
  bool synced = false;                 // the store has been read at least once

  std::map<std::int64_t, Reference> references;
  std::map<std::int64_t, std::vector<double>> darks;
  std::array<std::shared_ptr<const interp::SampleSet>, kQuantityCount> sets;
  std::array<std::size_t, kQuantityCount> skipped{};
  std::array<std::string, kQuantityCount> skipped_detail;
  std::list<CachedIndex> indexes;

  std::atomic<std::size_t> bytes{0};
  std::atomic<std::int64_t> announced_id{0};  // highest reading id reported (OnReading)
  std::atomic<std::uint64_t> used{0};         // IndexCache::tick_ of the last query
};

IndexCache::IndexCache(std::shared_ptr<storage::SessionStore> store, Options options)
    : store_(std::move(store)), options_(options) {}

void IndexCache::OnReading(SessionId session, const storage::ReadingRecord& reading) {
  std::shared_lock lock(mu_);
  auto it = entries_.find(session);
  if (it == entries_.end()) return;  // not cached: its first query reads everything anyway
  std::atomic<std::int64_t>& announced = it->second->announced_id;
  std::int64_t seen = announced.load();
  while (seen < reading.id && !announced.compare_exchange_weak(seen, reading.id)) {
  }
}

IndexCache::Stats IndexCache::stats() const {
  std::shared_lock lock(mu_);
  Stats s = stats_;
  s.hits += hits_.load();
  s.sessions = entries_.size();
  s.bytes = 0;
  for (const auto& [id, e] : entries_) s.bytes += e->bytes.load();
  return s;
}

namespace {

// Reads the session's record: whether it is anisotropic (its plan) and ρw.
Status LoadSession(storage::SessionStore& store, SessionId session, bool* anisotropic,
                   double* white_reflectance) {
  Result<storage::SessionRecord> rec = store.GetSession(session);
  if (!rec.ok()) return rec.status();
  Result<v1::Plan> plan = plan::ParsePlanJson(rec->plan_json);
  if (!plan.ok()) {
    return Internal("session " + std::to_string(session) +
                    ": its stored plan does not parse: " + plan.status().message());
  }
  *anisotropic = plan->anisotropic();
  if (rec->white_reflectance.has_value()) *white_reflectance = *rec->white_reflectance;
  return Status::Ok();
}

}  // namespace

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
  const IndexKey key = MakeKey(quantity, method, options);
  const int qi = static_cast<int>(quantity);
  std::shared_lock state(entry->state_mu);
  if (!entry->synced || announced > entry->through_id) return nullptr;
  for (const CachedIndex& cached : entry->indexes) {
    if (cached.key == key) {
      if (cached.index->samples != entry->sets[qi]) return nullptr;  // stale: extend or rebuild
      cached.used.store(now, std::memory_order_relaxed);
      hits_.fetch_add(1, std::memory_order_relaxed);
      return cached.index;
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
  std::shared_ptr<Entry> entry;
  {
    std::unique_lock lock(mu_);
    std::shared_ptr<Entry>& slot = entries_[session];
    if (!slot) slot = std::make_shared<Entry>();
    entry = slot;
  }
  entry->used.store(++tick_, std::memory_order_relaxed);
  auto forget = [&] {  // an entry that never loaded (unknown session, store error) is not kept
    std::unique_lock lock(mu_);
    auto it = entries_.find(session);
    if (it != entries_.end() && it->second == entry) entries_.erase(it);
  };

  std::unique_lock build(entry->build_mu);
  if (!entry->loaded) {
    Status st = LoadSession(*store_, session, &entry->anisotropic, &entry->white_reflectance);
    if (!st.ok()) {
      build.unlock();
      forget();
      return st;
    }
    entry->loaded = true;
  }
  const int dims = entry->anisotropic ? 4 : 3;

  // Read what landed since the last query (everything, the first time).
  const std::int64_t announced = entry->announced_id.load();
  bool appended = false;
  const bool first_load = !entry->synced;
  std::uint64_t read_now = 0;
  if (!entry->synced || announced > entry->through_id) {
    std::array<std::shared_ptr<interp::SampleSet>, kQuantityCount> next;
    auto add = [&](Quantity q, std::int64_t id, std::span<const double> coords,
                   const std::vector<double>& values) {
      auto& set = next[static_cast<int>(q)];
      if (!set) {
        const auto& old = entry->sets[static_cast<int>(q)];
        set = old ? std::make_shared<interp::SampleSet>(*old)
                  : std::make_shared<interp::SampleSet>(dims, static_cast<int>(values.size()));
      }
      return set->Add(id, coords, values);
    };
    // Committed to the entry only once every page was read: a store error leaves it as it was.
    std::int64_t through = entry->through_id;
    std::array<std::size_t, kQuantityCount> skipped = entry->skipped;
    std::array<std::string, kQuantityCount> skipped_detail = entry->skipped_detail;
    auto skip = [&](Quantity q, const std::string& why) {
      const int i = static_cast<int>(q);
      if (skipped[i]++ == 0) skipped_detail[i] = why;
    };

    for (;;) {
      Result<std::vector<storage::ReadingRecord>> page =
          store_->GetReadings(session, through, options_.page_size);
      if (!page.ok()) return page.status();
      read_now += page->size();
      for (const storage::ReadingRecord& r : *page) {
        through = std::max(through, r.id);
        switch (r.kind) {
          case storage::ReadingKind::kReference:
            entry->references[r.id] = Reference{r.spectrum, r.grid, r.directions.theta_i};
            continue;
          case storage::ReadingKind::kDark:
            entry->darks[r.id] = r.spectrum;
            continue;
          case storage::ReadingKind::kSample:
            break;
        }
        const std::string name = ReadingName(r);
        const Directions& d = r.directions;
        const bool finite = std::isfinite(d.theta_i) && std::isfinite(d.phi_i) &&
                            std::isfinite(d.theta_o) && std::isfinite(d.phi_o);
        if (!finite || !IsValid(d, 90.0)) {
          for (int q = 0; q < kQuantityCount; ++q) {
            skip(static_cast<Quantity>(q), name + ": lamp or detector below the surface");
          }
          continue;
        }
        if (!entry->grid.has_value()) entry->grid = r.grid;
        if (!(r.grid == *entry->grid)) {
          for (int q = 0; q < kQuantityCount; ++q) {
            skip(static_cast<Quantity>(q),
                 name + ": its wavelength grid differs from the session's first sample reading");
          }
          continue;
        }
        std::vector<double> coords;
        if (entry->anisotropic) {
          coords = {d.theta_i, d.phi_i, d.theta_o, d.phi_o};
        } else {
          const IsoDirection iso = ToIsotropic(d);
          coords = {iso.theta_i, iso.theta_o, iso.phi};
        }

        const Spectrum sample{r.grid, r.spectrum};
        std::optional<Spectrum> dark;
        if (r.dark_reading_id.has_value()) {
          auto it = entry->darks.find(*r.dark_reading_id);
          if (it == entry->darks.end()) {
            Result<storage::ReadingRecord> fetched = store_->GetReading(*r.dark_reading_id);
            if (fetched.ok() && fetched->kind == storage::ReadingKind::kDark) {
              it = entry->darks.emplace(fetched->id, fetched->spectrum).first;
            }
          }
          if (it == entry->darks.end() || it->second.size() != r.spectrum.size()) {
            for (int q = 0; q < kQuantityCount; ++q) {
              skip(static_cast<Quantity>(q), name + ": its dark reading " +
                                                 std::to_string(*r.dark_reading_id) +
                                                 " is missing or on another grid");
            }
            continue;
          }
          dark = Spectrum{r.grid, it->second};
        }

        // Radiance I − D.
        std::vector<double> radiance = r.spectrum;
        if (dark.has_value()) {
          for (std::size_t b = 0; b < radiance.size(); ++b) radiance[b] -= dark->values[b];
        }
        if (Status st = add(Quantity::kRadiance, r.id, coords, radiance); !st.ok()) {
          skip(Quantity::kRadiance, name + ": " + st.message());
        }

        // Reflectance and BRDF need the reference the reading names.
        const Reference* ref = nullptr;
        if (r.reference_reading_id.has_value()) {
          auto it = entry->references.find(*r.reference_reading_id);
          if (it == entry->references.end()) {
            Result<storage::ReadingRecord> fetched = store_->GetReading(*r.reference_reading_id);
            if (fetched.ok() && fetched->kind == storage::ReadingKind::kReference) {
              it = entry->references
                       .emplace(fetched->id, Reference{fetched->spectrum, fetched->grid,
                                                       fetched->directions.theta_i})
                       .first;
            }
          }
          if (it != entry->references.end()) ref = &it->second;
        }
        if (ref == nullptr) {
          const std::string why = r.reference_reading_id.has_value()
                                      ? name + ": its reference reading " +
                                            std::to_string(*r.reference_reading_id) + " is missing"
                                      : name + ": it names no reference reading";
          skip(Quantity::kReflectance, why);
          skip(Quantity::kBrdf, why);
          continue;
        }
        const Spectrum white{ref->grid, ref->spectrum};
        Result<Spectrum> reflectance =
            dark.has_value() ? Reflectance(sample, white, *dark) : Reflectance(sample, white);
        if (!reflectance.ok()) {
          skip(Quantity::kReflectance, name + ": " + reflectance.status().message());
          skip(Quantity::kBrdf, name + ": " + reflectance.status().message());
          continue;
        }
        if (Status st = add(Quantity::kReflectance, r.id, coords, reflectance->values); !st.ok()) {
          skip(Quantity::kReflectance, name + ": " + st.message());
        }
        Result<Spectrum> brdf =
            BrdfFromReflectance(*reflectance, entry->white_reflectance, ref->theta_i, d.theta_i);
        if (!brdf.ok()) {
          skip(Quantity::kBrdf, name + ": " + brdf.status().message());
          continue;
        }
        if (Status st = add(Quantity::kBrdf, r.id, coords, brdf->values); !st.ok()) {
          skip(Quantity::kBrdf, name + ": " + st.message());
        }
      }
      if (static_cast<int>(page->size()) < options_.page_size) break;
    }
    std::unique_lock state(entry->state_mu);
    entry->synced = true;
    entry->through_id = through;
    entry->skipped = skipped;
    entry->skipped_detail = std::move(skipped_detail);
    for (int q = 0; q < kQuantityCount; ++q) {
      if (next[q]) {
        entry->sets[q] = std::move(next[q]);
        appended = true;
      }
    }
    if (appended) {
      // Indexes over fewer readings are stale. Octant ones stay, to be extended on their next
      // query; the others are rebuilt then, so they need not be kept.
      entry->indexes.remove_if([&](const CachedIndex& cached) {
        const IndexSnapshot& index = *cached.index;
        return index.method != interp::Method::kOctant &&
               index.samples != entry->sets[static_cast<int>(index.quantity)];
      });
    }
  }

  const IndexKey key = MakeKey(quantity, method, options);
  const int qi = static_cast<int>(quantity);
  std::shared_ptr<const IndexSnapshot> stale;  // this key's index over fewer readings, if any
  for (auto it = entry->indexes.begin(); it != entry->indexes.end(); ++it) {
    if (it->key == key && it->index->samples != entry->sets[qi]) {
      stale = it->index;
      std::unique_lock state(entry->state_mu);
      entry->indexes.erase(it);
      break;
    }
    if (it->key == key) {
      std::shared_ptr<const IndexSnapshot> hit = it->index;
      it->used.store(++tick_, std::memory_order_relaxed);
      build.unlock();
      hits_.fetch_add(1, std::memory_order_relaxed);
      std::unique_lock lock(mu_);
      CountLoad(appended, first_load, read_now);
      return hit;
    }
  }

  // Options that do not fit the session are the caller's mistake, not the data's.
  if (!options.axis_scale.empty()) {
    if (static_cast<int>(options.axis_scale.size()) != dims) {
      return InvalidArgument("options.axis_scale: give " + std::to_string(dims) +
                             " values (one per axis, " +
                             (dims == 4 ? "θi, φi, θo, φo" : "θi, θo, φ") + ") or none, not " +
                             std::to_string(options.axis_scale.size()));
    }
    for (std::size_t i = 0; i < options.axis_scale.size(); ++i) {
      const double s = options.axis_scale[i];
      if (!std::isfinite(s) || s <= 0) {
        return InvalidArgument("options.axis_scale[" + std::to_string(i) +
                               "]: must be a finite number > 0 (got " + std::to_string(s) + ")");
      }
    }
  }
  if (dims == 4 && options.mirror_phi) {
    return InvalidArgument("options.mirror_phi: only for isotropic sessions; session " +
                           std::to_string(session) +
                           " is anisotropic (mirroring φ is not a symmetry of its sample)");
  }
  if (dims == 4 && options.reciprocity) {
    return InvalidArgument("options.reciprocity: only for isotropic sessions; session " +
                           std::to_string(session) + " is anisotropic");
  }

  const std::shared_ptr<const interp::SampleSet>& samples = entry->sets[qi];
  if (!samples || samples->size() == 0) {
    std::string message = "session " + std::to_string(session) + " has no sample reading with a " +
                          QuantityName(quantity) + " yet";
    if (entry->skipped[qi] > 0) {
      message += " (" + std::to_string(entry->skipped[qi]) +
                 " left out; the first: " + entry->skipped_detail[qi] + ")";
    } else {
      message += "; interpolate once the session has taken sample readings";
    }
    return FailedPrecondition(message);
  }

  // Extend the stale octant index when there is one (it was made with this key's options); a
  // fresh build otherwise, or if extending fails (it should not: the set only grew by Add).
  std::unique_ptr<interp::Interpolator> extended;
  bool extend_folded = false;
  if (stale != nullptr) {
    const auto* base = dynamic_cast<const interp::OctantInterpolator*>(stale->interpolator.get());
    if (base != nullptr) {
      Result<std::unique_ptr<interp::OctantInterpolator>> grown =
          interp::OctantInterpolator::Extend(*base, samples);
      if (grown.ok()) {
        extend_folded = (*grown)->tail_size() == 0;
        extended = std::move(grown).value();
      }
    }
    stale.reset();
  }
  const bool was_extended = extended != nullptr && !extend_folded;
  Result<std::unique_ptr<interp::Interpolator>> made =
      extended != nullptr ? Result<std::unique_ptr<interp::Interpolator>>(std::move(extended))
                          : interp::MakeInterpolator(method, samples, options);
  if (!made.ok()) {
    return FailedPrecondition("session " + std::to_string(session) + ": cannot build the " +
                              interp::MethodName(method) + " index over its " +
                              std::to_string(samples->size()) +
                              " sample reading(s): " + made.status().message() +
                              "; try another method or wait for more readings");
  }
  auto snapshot = std::make_shared<IndexSnapshot>();
  snapshot->session = session;
  snapshot->quantity = quantity;
  snapshot->method = method;
  snapshot->options = options;
  snapshot->anisotropic = entry->anisotropic;
  snapshot->dims = dims;
  snapshot->grid = entry->grid.value_or(WavelengthGrid::Pr650());
  snapshot->through_reading_id = entry->through_id;
  snapshot->skipped = entry->skipped[qi];
  snapshot->skipped_detail = entry->skipped_detail[qi];
  snapshot->samples = samples;
  snapshot->interpolator = std::shared_ptr<const interp::Interpolator>(std::move(*made));

  {
    std::unique_lock state(entry->state_mu);
    entry->indexes.emplace_back(key, snapshot, ++tick_);
    while (entry->indexes.size() > std::max<std::size_t>(1, options_.max_indexes_per_session)) {
      // The least recently queried one (the one just made has the newest tick).
      entry->indexes.erase(std::min_element(entry->indexes.begin(), entry->indexes.end(),
                                            [](const CachedIndex& a, const CachedIndex& b) {
                                              return a.used.load() < b.used.load();
                                            }));
    }
  }
  std::size_t bytes = 0;
  for (const auto& set : entry->sets) {
    if (set) bytes += SetBytes(*set);
  }
  for (const CachedIndex& cached : entry->indexes) bytes += IndexBytes(*cached.index->samples);
  entry->bytes = bytes;
  build.unlock();

  {
    std::unique_lock lock(mu_);
    ++(was_extended ? stats_.extends : stats_.builds);
    CountLoad(appended, first_load, read_now);
    Evict(session);
  }
  return std::shared_ptr<const IndexSnapshot>(std::move(snapshot));
}

void IndexCache::CountLoad(bool appended, bool first_load, std::uint64_t readings_read) {
  stats_.readings_read += readings_read;
  if (!appended) return;
  ++stats_.loads;
  if (!first_load) ++stats_.appends;
}

void IndexCache::Evict(SessionId keep) {
  auto total = [this] {
    std::size_t sum = 0;
    for (const auto& [id, e] : entries_) sum += e->bytes.load();
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

}  // namespace brdf::daemon
