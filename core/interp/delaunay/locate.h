// Point location in a Delaunay triangulation without Qhull: which simplex contains a query, and
// the query's barycentric coordinates in it.
//
// The triangulation is copied into flat arrays (vertices, neighbours, and per simplex the affine
// map from coordinates to barycentric coordinates, as scipy stores it), so a query touches no
// shared mutable state: Locate is const and safe from many threads at once.
//
// A query is found by a visibility walk: from a start simplex, step across the face whose
// barycentric coordinate is most negative until none is. In a Delaunay triangulation this walk
// cannot cycle in exact arithmetic; a step budget catches the rounding cases and falls back to a
// scan of every simplex. Stepping out through a hull face proves the query is outside the convex
// hull (hull faces are supporting hyperplanes), so outside queries end quickly too. The start
// comes from a uniform grid over the bounding box that remembers, for each cell, the simplex
// holding the cell's centre: random queries walk only a few steps. Callers with ordered queries
// can pass the previous answer's simplex, tried first.
#pragma once

#include <array>
#include <cstdint>
#include <span>
#include <vector>

#include "core/interp/delaunay/qhull.h"
#include "core/status.h"

namespace brdf::interp {

struct SimplexLocation {
  bool inside = false;
  // Inside: the enclosing simplex. Outside: the simplex the search ended at (near the query on
  // the hull), or -1 when there is none (the query is outside the bounding box, or not finite).
  std::int32_t simplex = -1;
  // Inside: barycentric weights of the simplex's vertices in vertex order (dims + 1 used),
  // each >= 0, summing to 1.
  std::array<double, 5> weights{};
};

class SimplexLocator {
 public:
  // `points`: count * dims coordinates (already scaled), the ones `triangulation` indexes.
  static Result<SimplexLocator> Build(std::span<const double> points, int dims,
                                      QhullTriangulation triangulation);

  int dims() const { return dims_; }
  std::size_t simplex_count() const { return simplex_count_; }
  // Heap of the simplices' records and the start grid (for memory bounds).
  std::size_t HeapBytes() const {
    return records3_.capacity() * sizeof(Record<3>) + records4_.capacity() * sizeof(Record<4>) +
           grid_.capacity() * sizeof(std::int32_t);
  }
  // Flat simplices (zero volume, from Qt on cospherical input): the walk passes through them but
  // never answers with one.
  std::size_t degenerate_count() const { return degenerate_count_; }
  // The dims + 1 point indices of `simplex`.
  std::span<const std::int32_t> vertices(std::int32_t simplex) const {
    const auto s = static_cast<std::size_t>(simplex);
    return dims_ == 3 ? std::span<const std::int32_t>(records3_[s].vertices)
                      : std::span<const std::int32_t>(records4_[s].vertices);
  }

  // `x` has dims() coordinates (scaled like the points). Starts from the grid.
  SimplexLocation Locate(std::span<const double> x) const;
  // Tries `hint` (a simplex of a previous answer) first: when it holds the query the answer
  // costs one barycentric evaluation; otherwise the walk starts from the grid. (Walking on from
  // a nearby hint measured no faster than the grid start, which is already within ~2 steps.)
  // Any hint is safe; a bad one only costs time.
  SimplexLocation LocateFrom(std::span<const double> x, std::int32_t hint) const;
  // Checks every simplex: the reference the walk must agree with, and its fallback.
  SimplexLocation LocateByScan(std::span<const double> x) const;

 private:
  // Everything a walk step reads about one simplex, in one place: for 3D exactly two cache
  // lines. transform = the inverse of [v0−vd … v(d−1)−vd] (D×D, row-major), then vd; its first
  // entry is NaN for a flat simplex. neighbours[m] is across the face opposite vertices[m], -1
  // on the hull.
  template <int D>
  struct alignas(64) Record {
    double transform[D * (D + 1)];
    std::int32_t vertices[D + 1];
    std::int32_t neighbours[D + 1];
  };

  SimplexLocator() = default;
  template <int D>
  const std::vector<Record<D>>& records() const;
  template <int D>
  std::vector<Record<D>>& records();
  template <int D>
  static Result<SimplexLocator> BuildFor(std::span<const double> points,
                                         const QhullTriangulation& triangulation);
  template <int D>
  void BuildRecords(std::span<const double> points, const QhullTriangulation& triangulation,
                    const std::vector<std::int32_t>& order);
  bool IsDegenerate(std::int32_t simplex) const;
  std::int32_t GridStart(const double* x) const;
  bool InBounds(const double* x) const;
  template <int D>
  void BuildGrid(std::size_t point_count);
  template <int D>
  SimplexLocation Walk(const double* x, std::int32_t start) const;
  template <int D>
  SimplexLocation Scan(const double* x) const;
  template <int D>
  SimplexLocation From(const double* x, std::int32_t hint) const;

  int dims_ = 0;
  std::size_t simplex_count_ = 0;
  std::size_t degenerate_count_ = 0;
  int max_steps_ = 0;
  // The simplices, sorted along a space-filling curve so that neighbours sit close in memory.
  // One of the two is used, by dims_.
  std::vector<Record<3>> records3_;
  std::vector<Record<4>> records4_;
  // Bounding box of the points and the start grid over it.
  std::array<double, 4> lower_{};
  std::array<double, 4> upper_{};
  std::array<double, 4> cells_per_unit_{};
  std::array<std::int64_t, 4> cell_counts_{};
  std::vector<std::int32_t> grid_;  // row-major, first axis slowest
};

}  // namespace brdf::interp
