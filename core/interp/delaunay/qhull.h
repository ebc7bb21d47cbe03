// The one place brdfd talks to Qhull: a Delaunay triangulation of points in 3 or 4 dimensions,
// returned as plain vertex lists so that nothing downstream depends on Qhull's data structures or
// keeps Qhull's memory alive. Pure: no I/O (Qhull's diagnostics go to an in-memory stream and
// end up in the error message).
#pragma once

#include <array>
#include <cstdint>
#include <span>
#include <vector>

#include "core/status.h"

namespace brdf::interp {

// A triangulation as plain arrays. Simplex s has vertices vertices[s*(dims+1) + m] (m = 0..dims)
// and, across the face opposite its vertex m, the neighbour neighbours[s*(dims+1) + m] (-1 where
// that face is on the convex hull).
struct QhullTriangulation {
  std::vector<std::int32_t> vertices;
  std::vector<std::int32_t> neighbours;
};

// Triangulates `points` (count * dims coordinates, row-major; dims 3 or 4) with scipy's options
// for Delaunay in up to 4 dimensions: "d Qt Qbb Qc Qz Q12" (Qt: triangulated output, so every
// cell is a simplex; Qz: a point at infinity, which keeps cospherical inputs such as regular
// grids from failing). Vertex numbers are indices into `points`.
// Points that Qhull merges away (near-coincident within its precision) are in no simplex.
// Qt may return flat (zero-volume) simplices for cospherical input; callers must cope.
// Errors: kInvalidArgument for degenerate input (all points on a hyperplane, too few points),
// with Qhull's own explanation appended.
Result<QhullTriangulation> TriangulateWithQhull(std::span<const double> points, int dims);

// The planes of the convex hull of `points` (count * 3 coordinates) by Qhull ("Qt"): per face
// its unit normal (pointing out) and offset, n·x + offset > 0 beyond it; every point is on the
// inner side up to Qhull's precision. Errors (kInvalidArgument): fewer than 4 points, all on one
// plane.
Result<std::vector<std::array<double, 4>>> ConvexHullPlanes3(std::span<const double> points);

}  // namespace brdf::interp
