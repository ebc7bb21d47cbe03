// ExportInterpolants: the interpolants Data.Export builds for grids, MERL and RGL (the chosen
// index, the fill chain's Delaunay fallback and its fitted model over the session's derived
// samples: core/export/fill/session_interpolant.h), kept per session snapshot, so that the next
// export of the same session with the same settings starts resampling at once instead of building
// them again (on a 50,000-reading session: ~0.9 s of model fit, ~0.7 s of Delaunay, the octant
// index and the derivation).
//
// Snapshot: a kept interpolant belongs to one copy of the session's readings, the one
// SharedSessionLoads (export_loads.h) handed out. The entry holds that copy, so Load keeps handing
// it out (after its one-record check) for as long as the store has no reading past it; once the
// session gains readings Load reads a new copy, which misses here, and keeping its interpolant
// drops those of the older copies. Settings: quantity, method, every interpolation option
// (axis scales, mirror_phi, reciprocity, coordinates, trend), fill policy, exclude_flagged.
//
// Each caller gets its own chain over the shared parts (ShareSessionInterpolant), so each export's
// report counts its own cells. One builder per snapshot and settings: a caller asking for what
// another is building waits for it; when that build fails (its own deadline or cancellation, or
// the readings), the waiters build again themselves. Failures are not kept.
//
// Memory: what the kept entries hold (estimated: each session copy and each set of derived
// samples once, however many entries share them; each entry's sample set and indexes) is reserved
// from the heavy calls' memory budget (memory_budget.h) for as long as it is held; at most
// Options::max_entries entries and max_bytes in all ([export] max_entries, max_mb), least
// recently used first out. The estimate is below resident memory: a paper-grid entry (2,112
// readings of 101 bands) counts 30.5 MB and holds 37–57 MB (daemon/DESIGN.md). An interpolant
// that does not fit, or whose reservation the budget refuses, is handed to its caller and not
// kept. Thread-safe.
#pragma once

#include <cstdint>
#include <functional>
#include <list>
#include <map>
#include <memory>
#include <string>

#include "core/export/fill/session_interpolant.h"
#include "core/mutex.h"
#include "core/readings/reading.h"
#include "core/status.h"
#include "daemon/config/config.h"
#include "daemon/rpc/memory_budget.h"

namespace brdf::daemon {

class ExportInterpolants {
 public:
  // The configuration's [export] table maps here (ExportInterpolantsOptionsFrom).
  struct Options {
    std::size_t max_entries = 4;
    // 0: half the memory budget.
    std::uint64_t max_bytes = 0;
  };
  // What an interpolant is built with, besides the session.
  struct Settings {
    exports::Quantity quantity = exports::Quantity::kBrdf;
    interp::Method method = interp::Method::kOctant;
    interp::Options options;
    exports::FillPolicy fill = exports::FillPolicy::kChain;
    bool exclude_flagged = false;
  };
  struct Stats {
    std::uint64_t hits = 0;       // answered from a kept interpolant (or one built meanwhile)
    std::uint64_t builds = 0;     // built by a caller
    std::uint64_t kept = 0;       // of those, kept
    std::uint64_t evictions = 0;  // dropped for room or for a newer copy of their session
    std::size_t entries = 0;      // kept now
    std::uint64_t bytes = 0;      // reserved now
  };
  using Build = std::function<Result<exports::SessionInterpolant>()>;

  // `budget` must outlive the cache.
  ExportInterpolants(MemoryBudget& budget, Options options);
  explicit ExportInterpolants(MemoryBudget& budget) : ExportInterpolants(budget, Options()) {}
  ExportInterpolants(const ExportInterpolants&) = delete;
  ExportInterpolants& operator=(const ExportInterpolants&) = delete;

  // The interpolant of `settings` over `session`: the kept one (a chain of its own over its
  // parts), else `build`'s (kept when it fits). `*built` (optional): whether this call built it.
  // Errors: `build`'s.
  Result<exports::SessionInterpolant> Get(const std::shared_ptr<const SessionReadings>& session,
                                          const Settings& settings, const Build& build,
                                          bool* built = nullptr);

  Stats stats() const;

  // The settings as a key: equal for settings that build the same interpolant.
  static std::string KeyOf(const Settings& settings);
  // An entry's own estimated memory: its sample set and indexes (not the session copy and the
  // derived samples it may share with others: SharedSessionLoads::BytesOf, DerivedBytes).
  static std::uint64_t OwnBytesOf(const exports::SessionInterpolant& in);
  static std::uint64_t DerivedBytes(const exports::DerivedSamples& derived);

 private:
  struct Entry {
    std::shared_ptr<const SessionReadings> session;
    std::string key;
    std::shared_ptr<const exports::SessionInterpolant> built;  // null while building
    std::uint64_t used = 0;                                    // recency tick
    std::unique_ptr<MemoryBudget::Reservation> reservation;
  };
  using Entries = std::list<Entry>;

  Entries::iterator Find(const SessionReadings* session, const std::string& key) REQUIRES(mu_);
  // The bytes kept now (entries and the parts they share).
  std::uint64_t KeptBytes() const REQUIRES(mu_);
  // Reserves `bytes` for `part` unless reserved already; false when the budget refuses.
  bool ReservePart(const std::shared_ptr<const void>& part, std::uint64_t bytes) REQUIRES(mu_);
  // Gives back the parts no kept entry holds any more.
  void ReleaseParts() REQUIRES(mu_);
  // Keeps `in` in `at` (reserved), or drops `at` when it does not fit.
  void Keep(Entries::iterator at, std::shared_ptr<const exports::SessionInterpolant> in)
      REQUIRES(mu_);
  // Drops the entries of older copies of `session`, then the least recently used beyond the
  // limits (never one being built, nor `keep`).
  void Evict(Entries::iterator keep) REQUIRES(mu_);

  MemoryBudget& budget_;
  const std::size_t max_entries_;
  const std::uint64_t max_bytes_;
  mutable Mutex mu_;
  CondVar landed_;  // a build ended (kept or not)
  Entries entries_ GUARDED_BY(mu_);
  // The shared parts (session copies, derived samples) reserved once while kept entries hold them.
  std::map<const void*, std::unique_ptr<MemoryBudget::Reservation>> parts_ GUARDED_BY(mu_);
  std::uint64_t tick_ GUARDED_BY(mu_) = 0;
  Stats stats_ GUARDED_BY(mu_);
};

// The cache's bounds from the configuration's [export] table (brdfd and brdf-archive alike).
ExportInterpolants::Options ExportInterpolantsOptionsFrom(const Config& config);

}  // namespace brdf::daemon
