// Delaunay interpolation of scattered spectra: the samples are triangulated once (Qhull), and a
// query is answered by the simplex that contains it, blending its dims+1 vertex spectra with the
// query's barycentric coordinates. This is what scipy's LinearNDInterpolator, Octave's and
// MATLAB's griddata do, and what the paper compares its octant method against.
//
// Called by MakeInterpolator (factory.cc) for Method::kDelaunay. Pure: no I/O.
//
// Rules where the interface leaves a choice:
// - Options.axis_scale multiplies coordinates before triangulating (the metric decides which
//   triangulation is "Delaunay"); vertex coordinates in answers are unscaled.
// - Symmetry augmentation (3D only), in this order: the measured samples; then, with mirror_phi,
//   (θi, θo, −φ) of each; then, with reciprocity, (θo, θi, φ) of every point so far. Copies keep
//   the id and SampleSet index of the sample they copy.
// - Coincident points (after scaling) keep the first in that order: a measured sample wins over
//   a copy, an earlier sample over a later one.
// - A query outside the convex hull answers kOutsideHull. A query beyond a hull face by less than
//   1e-10 of the simplex's size is inside (rounding on the data's boundary planes).
// - Weights are >= 0 and sum to 1 (rounding noise clamped), so every band lies between the
//   vertices' smallest and largest values.
#pragma once

#include <array>
#include <cstddef>
#include <cstdint>
#include <memory>
#include <span>
#include <vector>

#include "core/interp/interpolator.h"
#include "core/status.h"

namespace brdf::interp {

// The points the method triangulates: the cloud of point_cloud.h (measured samples, then
// symmetry copies, scaled) without coincident points (after scaling), each run of equal points
// kept at its lowest rank, in rank order. Errors: as BuildPointCloud.
struct DistinctCloud {
  int dims = 0;
  std::array<double, 4> scale{1, 1, 1, 1};
  std::vector<std::size_t> sample;  // per point: the SampleSet index it copies
  std::vector<double> coords;       // size() × dims, unscaled
  std::vector<double> scaled;       // size() × dims, scaled: what is triangulated

  std::size_t size() const { return sample.size(); }
  std::span<const double> point(std::size_t p) const {
    return {coords.data() + p * static_cast<std::size_t>(dims), static_cast<std::size_t>(dims)};
  }
  std::span<const double> scaled_point(std::size_t p) const {
    return {scaled.data() + p * static_cast<std::size_t>(dims), static_cast<std::size_t>(dims)};
  }
};
Result<DistinctCloud> DistinctDelaunayPoints(const SampleSet& samples, const Options& options);

// Triangulates `samples` (3D or 4D) after Options.axis_scale and symmetry augmentation.
// Errors: wrong dims, empty set, bad options, too few distinct points, degenerate input (all
// points on a plane / hyperplane) that Qhull cannot triangulate.
Result<std::unique_ptr<Interpolator>> MakeDelaunayInterpolator(
    std::shared_ptr<const SampleSet> samples, const Options& options);

// Where the previous answer was found. Ordered queries (along a scan, a space-filling curve, a
// rendering's neighbouring pixels) often fall in the same simplex; that simplex is tried first
// and, when it holds the query, no search is needed. One per thread or per sequence of queries;
// any value is safe.
struct LocateHint {
  std::int32_t simplex = -1;
};

class DelaunayInterpolator final : public Interpolator {
 public:
  static Result<std::unique_ptr<DelaunayInterpolator>> Create(
      std::shared_ptr<const SampleSet> samples, const Options& options);
  ~DelaunayInterpolator() override;

  Method method() const override { return Method::kDelaunay; }
  int dims() const override;
  std::size_t HeapBytes() const override;
  // Thread-safe. The search starts from a precomputed simplex near the query.
  Interpolation Evaluate(std::span<const double> query) const override;
  // Thread-safe for distinct hints. Tries hint.simplex first (else searches as Evaluate does)
  // and stores the answer's simplex back (unchanged when the query is outside the hull).
  Interpolation EvaluateFrom(std::span<const double> query, LocateHint& hint) const;
  // queries: n * dims() coordinates, row-major. Fills `out` with n answers, each trying the
  // previous answer's simplex first: fastest when consecutive queries are close. Errors when
  // queries.size() is not a multiple of dims().
  Status EvaluateBatch(std::span<const double> queries, std::vector<Interpolation>& out) const;
  // The spectrum alone, for bulk work (rendering, resampling, benchmarks against scipy, which
  // returns values only): no provenance, no allocation. spectrum.size() must be the sample
  // set's band count. Returns kOk (spectrum filled) or kOutsideHull (spectrum untouched); a
  // query or spectrum of the wrong size is kOutsideHull too. Thread-safe for distinct hints.
  InterpStatus EvaluateSpectrum(std::span<const double> query, std::span<double> spectrum,
                                LocateHint& hint) const;

  // Distinct points triangulated (after augmentation and removal of coincident points).
  std::size_t point_count() const;
  std::size_t simplex_count() const;
  // Flat simplices Qhull's Qt produced (cospherical input such as regular grids); never answers.
  std::size_t flat_simplex_count() const;

 private:
  struct Impl;
  explicit DelaunayInterpolator(std::unique_ptr<const Impl> impl);
  std::unique_ptr<const Impl> impl_;
};

}  // namespace brdf::interp
