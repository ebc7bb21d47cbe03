// The Delaunay method's answer at a few directions without triangulating every sample: each
// query is answered from a triangulation of the points nearest it, and only when that answer is
// proved to be the whole triangulation's (else the caller builds the whole one). For a session of
// 50,000 readings mirrored and swapped (~200,000 points) the whole triangulation takes seconds;
// a query near the data answers here in milliseconds (the lit sphere's colour at 45°:0°, on the
// readings' edge θo = 0 where the octant method has no value: daemon/api/appearance.cc).
//
// Why the answer is the whole triangulation's. The points are DistinctDelaunayPoints' (the ones
// DelaunayInterpolator triangulates), so the whole triangulation T is CGAL's of that set, which
// is unique even for cospherical points (symbolic perturbation decided by the points alone, not
// their order). Let S' be the k points nearest the query and σ the simplex of CGAL's
// triangulation of S' that the locator (locate.h, the same rules and tolerances) finds holding the
// query. When every point outside S' lies strictly outside σ's circumsphere (exact predicate),
// σ's circumsphere is empty of all points under the same perturbation, so σ is a simplex of T,
// and T's locator finds the query in σ or, on a face of σ, in a neighbour sharing that face: the
// same linear interpolant there. The blend is the same weights of the same vertex spectra; the
// weights are computed from σ's vertices in the order this triangulation lists them, so a band
// may differ from the whole triangulation's in its last bits (rounding), never more.
// A query outside the bounding box of all points is outside T's hull (the locator's first test,
// the same comparisons): answered kOutsideHull. So is a query beyond a face of the points'
// convex hull (Qhull's, made at the first query that needs it: ~0.1 s for 200,000 points) by more
// than 1e-7 of the bounding box's diagonal, every point being on the face's inner side up to
// rounding: T's locator forgives a query beyond the hull by a barycentric coordinate of −1e-10
// (locate.cc's kHullEps), far less, so it finds it outside too. Anything else is not proved here.
//
// 3D (isotropic) only. Pure: no I/O.
#pragma once

#include <array>
#include <cstddef>
#include <cstdint>
#include <memory>
#include <mutex>
#include <optional>
#include <span>
#include <vector>

#include "core/interp/delaunay/delaunay.h"
#include "core/interp/delaunay/qhull.h"
#include "core/interp/interpolator.h"
#include "core/status.h"

namespace brdf::interp {

class NearDelaunay {
 public:
  // The distinct points of `samples` under `options` (as DelaunayInterpolator::Create takes
  // them; sorting them is most of the cost, ~0.1 s for 200,000 points). Errors: 4D samples,
  // options MakeInterpolator answers through a wrapper (half/difference coordinates, a trend),
  // and DistinctDelaunayPoints' errors.
  static Result<NearDelaunay> Create(std::shared_ptr<const SampleSet> samples,
                                     const Options& options);

  // The whole triangulation's answer at `query` (θi, θo, φ): kOk with `spectrum` (the sample
  // set's bands() values) written, or kOutsideHull; nullopt when it could not be proved from up
  // to `most_points` nearest points (then ask DelaunayInterpolator). Thread-safe (const).
  std::optional<InterpStatus> SpectrumAt(std::span<const double> query, std::span<double> spectrum,
                                         std::size_t most_points = 4096) const;

  std::size_t point_count() const { return cloud_.size(); }

 private:
  NearDelaunay(std::shared_ptr<const SampleSet> samples, DistinctCloud cloud);
  // The answer from the `k` points nearest `x` (scaled), or nullopt when not proved.
  std::optional<InterpStatus> FromNearest(const double* x, std::size_t k,
                                          std::span<double> spectrum) const;

  // The planes of the points' convex hull (made at the first OutsideAll).
  struct HullPlane {
    std::array<double, 3> normal;  // unit, outwards
    double offset = 0;             // normal·x + offset: how far x is beyond the plane
  };
  struct Hull {
    std::once_flag once;
    bool made = false;
    std::vector<HullPlane> planes;
  };
  Status MakeHull() const;
  static double Height(const HullPlane& plane, const double* p);
  // Whether `x` (scaled) is beyond a hull plane by more than the locator's tolerance could reach
  // (kBeyond), every point being on its inner side (within rounding, kOnPlane).
  bool OutsideAll(const double* x) const;

  std::shared_ptr<const SampleSet> samples_;
  DistinctCloud cloud_;
  std::array<double, 3> lower_{};  // bounding box of the scaled points
  std::array<double, 3> upper_{};
  double diagonal_ = 0;         // of the bounding box
  std::unique_ptr<Hull> hull_;  // thread-safe: made once
};

}  // namespace brdf::interp
