// The 3-D Delaunay triangulation by CGAL (Delaunay_triangulation_3 with exact predicates), for
// isotropic sessions: the same plain arrays as Qhull's (qhull.h), built in a small fraction of
// Qhull's time on the degenerate point sets a rig produces (a regular grid of poses is
// cospherical everywhere, and Qhull spends most of its time merging facets there; CGAL resolves
// such ties by symbolic perturbation instead). Pure: no I/O.
#pragma once

#include <array>
#include <cstdint>
#include <span>
#include <vector>

#include "core/interp/delaunay/qhull.h"
#include "core/status.h"

namespace brdf::interp {

// Triangulates `points` (count * 3 coordinates, row-major, no two equal). Every finite cell of
// the result has positive volume (exact orientation), so there are no flat simplices. For
// cospherical input any of the valid Delaunay triangulations may come back; it is the same one for
// the same input. Vertex numbers are indices into `points`.
// Errors: kInvalidArgument for fewer than 4 points or all points on one plane (naming what to
// measure).
Result<QhullTriangulation> TriangulateWithCgal3(std::span<const double> points);

// Whether every point of `points` (count * 3 coordinates) for which `exempt` is false lies
// strictly outside the sphere through the four points `cell` (indices into `points`, not on one
// plane), decided by CGAL's exact predicate: a point on the sphere counts as not outside.
bool OutsideCircumsphere(std::span<const double> points, const std::array<std::int32_t, 4>& cell,
                         const std::vector<bool>& exempt);

}  // namespace brdf::interp
