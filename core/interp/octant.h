// The paper's octant method (Sun & Wang, "Interpolation"), made exact by
// ../../../shared/reference/interpolation.md: around the query P, the nearest sample in each of
// the 2^dims orthants cut by the axis planes through P; the first simplex of the cube of winners
// (3D: ABCF, ACDH, AEFH, CFGH, ACFH; 4D: the 24 Kuhn simplices) that encloses P; the vertex
// spectra blended with P's barycentric weights. Everything happens in the scaled space of
// Options.axis_scale, over the samples plus their symmetry copies (point_cloud.h).
//
// Two implementations give bit-identical answers (same vertices, weights, statuses, spectra):
//   MakeOctantInterpolator:          the nearest point per orthant from a k-d tree (kd_tree.h);
//                                    what MakeInterpolator(Method::kOctant) returns.
//   MakeOctantReferenceInterpolator: the paper's O(N) scan (octant_reference.h), for tests and
//                                    `brdf-interp --method octant-reference`.
//
// Not a property of the method: exactness at the data points. When P is a sample, that sample
// wins the (+,+,+) orthant, but an earlier tetrahedron without it can still enclose P (about a
// quarter of the time on uniform random data); then the answer blends its neighbours. On a regular
// lattice the answer at a lattice point is exact.
//
// A query with the wrong number of coordinates or a non-finite one is answered kEmptyOctant
// (no orthant of it holds a sample), with a detail that says so.
#pragma once

#include <memory>

#include "core/interp/interpolator.h"
#include "core/status.h"

namespace brdf::interp {

// Errors (kInvalidArgument): null or empty samples, not 3D/4D, bad options (ValidateOptions).
Result<std::unique_ptr<Interpolator>> MakeOctantInterpolator(
    std::shared_ptr<const SampleSet> samples, const Options& options = {});

}  // namespace brdf::interp
