// The index part of IndexCache: what identifies an index within a session (IndexKey), whether a
// query's options fit the session, and making an index over a sample set (a fresh build, or an
// extension of the octant index over fewer readings). Stateless functions; IndexCache keeps the
// results.
#pragma once

#include <cstdint>
#include <memory>
#include <vector>

#include "core/interp/interpolator.h"
#include "core/readings/quantity.h"
#include "core/status.h"

namespace brdf::daemon {

struct IndexSnapshot;

// What identifies an index within a session.
struct IndexKey {
  Quantity quantity;
  interp::Method method;
  std::vector<double> axis_scale;  // normalised: empty when all 1
  bool mirror_phi;
  bool reciprocity;
  interp::Coordinates coordinates;  // an index never answers in the other coordinates
  interp::Trend trend;
  bool operator==(const IndexKey& o) const;
};

IndexKey MakeIndexKey(Quantity quantity, interp::Method method, const interp::Options& options);

// kInvalidArgument (naming "options.axis_scale", "options.mirror_phi", "options.reciprocity",
// "options.coordinates": half/difference on an anisotropic session; "options.trend": a trend on
// an anisotropic session) when the options do not fit
// a session of `dims` coordinates.
Status CheckIndexOptions(const interp::Options& options, int dims, std::int64_t session);

// kFailedPrecondition when the session has no sample reading with the quantity yet (naming how
// many were left out and why the first one was).
Status CheckHasSamples(const interp::SampleSet* samples, Quantity quantity, std::size_t skipped,
                       const std::string& skipped_detail, std::int64_t session);

struct MadeIndex {
  std::unique_ptr<interp::Interpolator> interpolator;
  bool extended = false;  // the stale octant index was extended (not a build)
};

// The index over `samples`: `stale`'s octant index extended when it is one (made with these
// options over fewer readings; incidence coordinates only) and the extension keeps its tree,
// else a fresh build (half/difference indexes are always rebuilt). Errors:
// kFailedPrecondition naming the method and what to do.
Result<MadeIndex> MakeIndex(std::shared_ptr<const interp::SampleSet> samples, interp::Method method,
                            const interp::Options& options, const IndexSnapshot* stale,
                            std::int64_t session);

// Memory for the caches' bounds: a set's samples (its chunks, shared with other snapshots or
// not). An index's own is interp::Interpolator::HeapBytes (its copies and images of the
// coordinates, its tree or triangulation, the sets it made; a Delaunay index over a set's mirror
// images is about 2.8 kB a sample, an octant one about 0.3 kB).
std::size_t SetBytes(const interp::SampleSet& set);

}  // namespace brdf::daemon
