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

}  // namespace

struct IndexCache::Entry {
  std::mutex build_mu;  // guards everything below except announced_id and bytes

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
  std::list<std::pair<IndexKey, std::shared_ptr<const IndexSnapshot>>> indexes;  // MRU first

  std::atomic<std::size_t> bytes{0};
  std::int64_t announced_id = 0;  // guarded by IndexCache::mu_: highest reading id reported
};

IndexCache::IndexCache(std::shared_ptr<storage::SessionStore> store, Options options)
    : store_(std::move(store)), options_(options) {}

void IndexCache::OnReading(SessionId session, const storage::ReadingRecord& reading) {
  std::lock_guard lock(mu_);
  auto it = entries_.find(session);
  if (it == entries_.end()) return;  // not cached: its first query reads everything anyway
  it->second->announced_id = std::max(it->second->announced_id, reading.id);
}

IndexCache::Stats IndexCache::stats() const {
  std::lock_guard lock(mu_);
  Stats s = stats_;
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

Result<std::shared_ptr<const IndexSnapshot>> IndexCache::Get(SessionId session, Quantity quantity,
                                                             interp::Method method,
                                                             const interp::Options& options) {
  std::shared_ptr<Entry> entry;
  {
    std::lock_guard lock(mu_);
    std::shared_ptr<Entry>& slot = entries_[session];
    if (!slot) slot = std::make_shared<Entry>();
    entry = slot;
    lru_.remove(session);
    lru_.push_front(session);
  }
  auto forget = [&] {  // an entry that never loaded (unknown session, store error) is not kept
    std::lock_guard lock(mu_);
    auto it = entries_.find(session);
    if (it != entries_.end() && it->second == entry) {
      entries_.erase(it);
      lru_.remove(session);
    }
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
  std::int64_t announced = 0;
  {
    std::lock_guard lock(mu_);
    announced = entry->announced_id;
  }
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
      entry->indexes.remove_if([&](const auto& cached) {
        const IndexSnapshot& index = *cached.second;
        return index.method != interp::Method::kOctant &&
               index.samples != entry->sets[static_cast<int>(index.quantity)];
      });
    }
  }

  const IndexKey key = MakeKey(quantity, method, options);
  const int qi = static_cast<int>(quantity);
  std::shared_ptr<const IndexSnapshot> stale;  // this key's index over fewer readings, if any
  for (auto it = entry->indexes.begin(); it != entry->indexes.end(); ++it) {
    if (it->first == key && it->second->samples != entry->sets[qi]) {
      stale = std::move(it->second);
      entry->indexes.erase(it);
      break;
    }
    if (it->first == key) {
      std::shared_ptr<const IndexSnapshot> hit = it->second;
      entry->indexes.splice(entry->indexes.begin(), entry->indexes, it);
      build.unlock();
      std::lock_guard lock(mu_);
      ++stats_.hits;
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

  entry->indexes.emplace_front(key, snapshot);
  while (entry->indexes.size() > std::max<std::size_t>(1, options_.max_indexes_per_session)) {
    entry->indexes.pop_back();
  }
  std::size_t bytes = 0;
  for (const auto& set : entry->sets) {
    if (set) bytes += SetBytes(*set);
  }
  for (const auto& [k, index] : entry->indexes) bytes += IndexBytes(*index->samples);
  entry->bytes = bytes;
  build.unlock();

  {
    std::lock_guard lock(mu_);
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
  while (!lru_.empty() && lru_.back() != keep &&
         (entries_.size() > std::max<std::size_t>(1, options_.max_sessions) ||
          total() > options_.max_bytes)) {
    entries_.erase(lru_.back());
    lru_.pop_back();
    ++stats_.evictions;
  }
}

}  // namespace brdf::daemon
