// The CSV that brdf-interp writes: one row per query, in query order.
//
//   <coordinates>,status,<one column per wavelength>[,v0,…,v{k−1},w0,…,w{k−1},detail]
//
// Coordinates are the query's, named as in the queries file. status is InterpStatusName
// ("ok", "empty_octant", "no_enclosing_simplex", "outside_hull"). The spectral columns carry the
// samples file's wavelength headers; they are empty when status is not ok. With --explain, k
// vertex columns give the 0-based data row (in the samples file) of each blended sample and k
// weight columns its weight, where k is the most vertices the method uses (octant and Delaunay:
// dims + 1, nearest: 1), in the method's vertex order (octant: the tetrahedron's letters, e.g.
// A, C, F, H); then a free-text detail (which tetrahedron, which octant was empty), quoted.
// Numbers are written in the shortest form that reads back to the same double.
#pragma once

#include <span>
#include <string>
#include <vector>

#include "core/interp/interpolator.h"

namespace brdf::interp_tool {

struct OutputLayout {
  int dims = 3;
  std::vector<std::string> wavelength_headers;
  int explain_vertices = 0;  // k above; 0 without --explain
};

// The most vertices an answer of `method` has for `dims`-dimensional data.
int MaxVertices(interp::Method method, int dims);

std::string FormatHeader(const OutputLayout& layout);
// Appends one row (with its newline).
void AppendRow(const OutputLayout& layout, std::span<const double> query,
               const interp::Interpolation& answer, std::string& out);
// Shortest round-trip decimal form of x.
void AppendNumber(double x, std::string& out);

}  // namespace brdf::interp_tool
