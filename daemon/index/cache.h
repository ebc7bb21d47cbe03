// IndexCache: the interpolation indexes the Interpolation service answers from, one per
// (session, quantity, method, options: scales, symmetries, coordinates), built from the
// session's SAMPLE readings with core/interp's MakeInterpolator.
//
// Quantities (core/readings/quantity.h, derived by core/readings/derive.h, the same derivation
// the exports use), per sample reading I:
//   radiance     I − D                                  (D: the dark the reading names, if any)
//   reflectance  (I − D) / (I0 − D)                     (I0: the reference the reading names)
//   BRDF         R · ρw / π · cos θi,ref / cos θi       (θi,ref: the reference reading's θi;
//                                                        ρw: the session's white reflectance)
// Coordinates: (θi, θo, φ) for isotropic plans (3D), (θi, φi, θo, φo) for anisotropic ones (4D),
// from each reading's stored directions. Flagged readings are kept (the quality policy chose to
// keep them); a reading whose quantity cannot be computed (no reference, a reference too dark in
// a band, a different wavelength grid, directions below the surface) is left out and counted in
// the snapshot's `skipped`, with the first reason.
//
// Freshness and consistency: a snapshot is immutable. Readers hold a shared_ptr<const
// IndexSnapshot> for as long as they need it (a whole batch), so they always see one consistent
// set of readings even while new readings land. OnReading (registered as a SessionManager
// reading listener; quick, never touches the store) hands over the record the executor just
// committed; the cache keeps it with the session and the next Get folds it in (index_samples.h:
// core/readings' derivation, from the reference and dark it names, which the cache has folded
// before) and publishes new sample sets. Only a first load (a session not cached yet, or evicted)
// reads the store. A new set is a copy of the old one that shares its storage
// (interp::SampleSet's chunks) plus the new readings, so an append costs the new readings, not
// the session. The octant index (the paper's method, the default) is then extended, not rebuilt:
// interp::OctantInterpolator::Extend shares the old snapshot's search tree and scans the new
// readings beside it (answers identical to a fresh build; it folds them into a fresh tree now and
// then, which counts as a build). Delaunay and nearest-neighbour indexes, and every index in
// half/difference coordinates, are rebuilt over the grown set on their next query. Older
// snapshots are never changed. The coordinates are part of an index's key (index_build.h), so an
// index never answers a query in the other coordinates.
//
// Memory: the cache keeps at most Options::max_sessions sessions and about Options::max_bytes of
// samples and indexes, evicting the least recently used session; each session keeps at most
// max_indexes_per_session indexes (least recently used first out). An evicted session is simply
// rebuilt from the store on its next query, and so is one whose handed-over records, waiting to
// be folded, outgrow max_bytes (a session measured for long without a query). Snapshots still
// held by readers stay valid.
//
// Files: index_cache.{h,cc} (lookup, append, build, memory, eviction), index_samples.{h,cc} (a
// session's sample sets grown a reading at a time), index_build.{h,cc} (keys, option checks,
// build or extend).
#pragma once

#include <atomic>
#include <cstdint>
#include <functional>
#include <list>
#include <map>
#include <memory>
#include <mutex>
#include <shared_mutex>
#include <string>
#include <utility>
#include <vector>

#include "core/interp/interpolator.h"
#include "core/readings/quantity.h"
#include "core/status.h"
#include "core/wavelength_grid.h"
#include "daemon/config/config.h"
#include "daemon/index/budgets.h"
#include "daemon/index/interpolation_calibration.h"
#include "daemon/sessions/session_id.h"
#include "daemon/sessions/session_plan.h"
#include "storage/records.h"
#include "storage/session_reader.h"
#include "storage/session_store.h"

namespace brdf::daemon {

// Quantity, kQuantityCount and QuantityName are core/readings' (quantity.h).

// One index, ready for queries. Immutable once published; Evaluate is thread-safe.
struct IndexSnapshot {
  SessionId session = 0;
  Quantity quantity = Quantity::kBrdf;
  interp::Method method = interp::Method::kOctant;
  interp::Options options;
  bool anisotropic = false;
  int dims = 3;  // 3: (θi, θo, φ); 4: (θi, φi, θo, φo)
  WavelengthGrid grid;
  // Every reading of the session with id ≤ this was considered.
  std::int64_t through_reading_id = 0;
  // Sample readings left out for this quantity, and why the first one was.
  std::size_t skipped = 0;
  std::string skipped_detail;
  std::shared_ptr<const interp::SampleSet> samples;
  std::shared_ptr<const interp::Interpolator> interpolator;
  // BRDF snapshots: the samples' uncertainty budgets, position for position (null: not
  // estimated); empty for other quantities (the stored budgets are of the BRDF).
  BudgetList budgets;
  // The interpolation term's calibration from held-out readings, computed on the first answer
  // with uncertainty (interpolation_calibration.h); never null in a published snapshot.
  std::shared_ptr<const CalibrationSlot> calibration = std::make_shared<CalibrationSlot>();
};

struct IndexKey;  // index_build.h

class IndexCache {
 public:
  struct Options {
    std::size_t max_sessions = 8;
    std::size_t max_bytes = std::size_t{512} << 20;
    std::size_t max_indexes_per_session = 12;
    // Readings fetched per store page while loading.
    int page_size = 512;
  };

  struct Stats {
    std::size_t sessions = 0;           // sessions cached now
    std::size_t bytes = 0;              // estimated memory held now
    std::uint64_t loads = 0;            // times readings were added: a first load or an append
    std::uint64_t appends = 0;          // of those, appends of committed records to samples already
                                        // held (no store read)
    std::uint64_t readings_read = 0;    // readings fetched from the store, all sessions: only
                                        // first loads read it
    std::uint64_t readings_folded = 0;  // committed records handed over by OnReading and folded
    std::uint64_t builds = 0;           // indexes built from scratch (all their readings)
    std::uint64_t extends = 0;          // octant indexes extended by the readings that landed
                                        // (the search tree shared with the previous snapshot)
    std::uint64_t hits = 0;             // queries answered from a cached index
    std::uint64_t evictions = 0;        // sessions evicted
  };

  // Where the cache gets a session's plan (whether it is anisotropic): in brdfd the
  // SessionManager's, parsed once (SessionManager::Plan). Without one, the cache parses the
  // stored record on a first load (ParseSessionPlan), as a standalone cache must.
  using PlanSource = std::function<Result<std::shared_ptr<const SessionPlan>>(SessionId)>;

  // `store`: where a first load reads the session (the rig's SessionStore; brdf-archive's
  // storage::ArchiveReader).
  IndexCache(std::shared_ptr<storage::SessionReader> store, Options options,
             PlanSource plans = nullptr);
  explicit IndexCache(std::shared_ptr<storage::SessionReader> store)
      : IndexCache(std::move(store), Options()) {}
  IndexCache(const IndexCache&) = delete;
  IndexCache& operator=(const IndexCache&) = delete;

  // A reading was committed (SessionManager::AddReadingListener): `reading` is the stored record
  // (with its id). Kept for the session's next Get to fold in; ignored when the session is not
  // cached (its first load reads it from the store). Never blocks on a build or the store.
  void OnReading(SessionId session, const storage::ReadingRecord& reading);

  // The index for these settings over every reading committed so far: the cached one, else
  // appended (the records handed over since) and extended or built. Errors:
  //   kNotFound            no such session;
  //   kInvalidArgument     options that do not fit the session (naming "options.axis_scale",
  //                        "options.mirror_phi", "options.reciprocity", "options.coordinates");
  //   kFailedPrecondition  no usable sample reading yet, or the readings cannot be indexed by
  //                        this method (e.g. Delaunay on readings that all lie in one plane);
  //   kIoError             the store could not be read (first load).
  Result<std::shared_ptr<const IndexSnapshot>> Get(SessionId session, Quantity quantity,
                                                   interp::Method method,
                                                   const interp::Options& options);

  // The cached, current index for these settings when no reading landed since the session's
  // samples were last published: the common query, answered under shared locks only (no store read,
  // no build, no allocation), so concurrent queries never wait for each other and a caller that
  // must not block can ask. Null otherwise (then Get loads, extends or builds).
  std::shared_ptr<const IndexSnapshot> FreshHit(SessionId session, Quantity quantity,
                                                interp::Method method,
                                                const interp::Options& options);

  Stats stats() const;

  // The sessions cached and loaded, each with the highest reading id it holds (folded or handed
  // over). A server without commit events (brdf-archive) asks its store for the readings above
  // it now and then and hands them over with OnReading, so that a session still being recorded
  // (or shipped) grows as it does on the rig.
  std::vector<std::pair<SessionId, std::int64_t>> HeldThrough() const;

 private:
  struct Entry;
  // The steps of Get, in order. Lookup finds or adds the session's entry (mu_ exclusive for an
  // add). The rest run with the entry's build lock held: Load reads a cold session from the
  // store; Append folds the records handed over since and publishes the grown sets; Build
  // makes the index (index_build.h: extending a stale octant one) and Keep caches it.
  std::shared_ptr<Entry> Lookup(SessionId session);
  void Forget(SessionId session, const std::shared_ptr<Entry>& entry);
  Status Load(Entry& entry, SessionId session, std::uint64_t* read);
  bool Append(Entry& entry, std::uint64_t* folded);
  std::shared_ptr<const IndexSnapshot> FindIndex(Entry& entry, const IndexKey& key,
                                                 std::shared_ptr<const IndexSnapshot>* stale);
  void Keep(Entry& entry, const IndexKey& key, std::shared_ptr<const IndexSnapshot> index);
  // Memory of the entry's sets and indexes (its build lock held).
  static std::size_t EntryBytes(const Entry& entry);
  void Evict(SessionId keep);
  // Counts in stats_ (mu_ held exclusively).
  struct Counts {
    bool appended = false;    // a set grew
    bool first_load = false;  // from the store
    std::uint64_t read = 0;
    std::uint64_t folded = 0;
  };
  void Count(const Counts& counts);

  std::shared_ptr<storage::SessionReader> store_;
  Options options_;
  PlanSource plans_;

  // Guards everything below (never held while building): shared to look an entry up, exclusive
  // to add, evict or count. Recency is a tick per entry (Entry::used), not a list, so that a
  // query only reads the map.
  mutable std::shared_mutex mu_;
  std::map<SessionId, std::shared_ptr<Entry>> entries_;
  Stats stats_;
  std::atomic<std::uint64_t> hits_{0};  // Stats::hits (counted without mu_)
  std::atomic<std::uint64_t> tick_{0};  // recency clock of entries and indexes
};

// The cache's bounds from the configuration's [index] table (max_sessions, max_mb), the same in
// brdfd and brdf-archive.
IndexCache::Options IndexCacheOptionsFrom(const Config& config);

}  // namespace brdf::daemon
