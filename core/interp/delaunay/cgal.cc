#include "core/interp/delaunay/cgal.h"

#include <CGAL/Delaunay_triangulation_3.h>
#include <CGAL/Exact_predicates_inexact_constructions_kernel.h>
#include <CGAL/Triangulation_cell_base_with_info_3.h>
#include <CGAL/Triangulation_vertex_base_with_info_3.h>

#include <cstdint>
#include <string>
#include <utility>
#include <vector>

namespace brdf::interp {
namespace {

using Kernel = CGAL::Exact_predicates_inexact_constructions_kernel;
using VertexBase = CGAL::Triangulation_vertex_base_with_info_3<std::int32_t, Kernel>;
using CellBase = CGAL::Delaunay_triangulation_cell_base_3<Kernel>;
using CellWithIndex = CGAL::Triangulation_cell_base_with_info_3<std::int32_t, Kernel, CellBase>;
using DataStructure = CGAL::Triangulation_data_structure_3<VertexBase, CellWithIndex>;
using Delaunay3 = CGAL::Delaunay_triangulation_3<Kernel, DataStructure>;

}  // namespace

Result<QhullTriangulation> TriangulateWithCgal3(std::span<const double> points) {
  const std::size_t count = points.size() / 3;
  if (count < 4) {
    return InvalidArgument("Delaunay triangulation: " + std::to_string(count) +
                           " distinct sample points, need at least 4 not on one plane; measure "
                           "more poses");
  }
  if (count > 0x7fffffff) {
    return InvalidArgument("Delaunay triangulation: " + std::to_string(count) +
                           " points exceed the triangulation's limit; thin the sample set");
  }
  std::vector<std::pair<Kernel::Point_3, std::int32_t>> input;
  input.reserve(count);
  for (std::size_t i = 0; i < count; ++i) {
    input.emplace_back(Kernel::Point_3(points[3 * i], points[3 * i + 1], points[3 * i + 2]),
                       static_cast<std::int32_t>(i));
  }
  // Range insertion sorts the points along a space-filling curve first (CGAL's spatial_sort).
  Delaunay3 triangulation(input.begin(), input.end());
  if (triangulation.dimension() < 3) {
    return InvalidArgument("Delaunay triangulation of " + std::to_string(count) +
                           " points failed: they lie on one plane (dimension " +
                           std::to_string(triangulation.dimension()) +
                           "); measure poses that vary in every coordinate");
  }

  std::int32_t cells = 0;
  for (auto cell = triangulation.all_cells_begin(); cell != triangulation.all_cells_end(); ++cell) {
    cell->info() = triangulation.is_infinite(cell) ? -1 : cells++;
  }
  QhullTriangulation out;
  out.vertices.reserve(static_cast<std::size_t>(cells) * 4);
  out.neighbours.reserve(out.vertices.capacity());
  for (auto cell = triangulation.finite_cells_begin(); cell != triangulation.finite_cells_end();
       ++cell) {
    // CGAL's neighbour(m) is across the face opposite vertex(m), as QhullTriangulation wants.
    for (int m = 0; m < 4; ++m) {
      out.vertices.push_back(cell->vertex(m)->info());
      out.neighbours.push_back(cell->neighbor(m)->info());
    }
  }
  return out;
}

bool OutsideCircumsphere(std::span<const double> points, const std::array<std::int32_t, 4>& cell,
                         const std::vector<bool>& exempt) {
  const auto at = [&points](std::size_t i) {
    return Kernel::Point_3(points[3 * i], points[3 * i + 1], points[3 * i + 2]);
  };
  std::array<Kernel::Point_3, 4> corner;
  for (std::size_t m = 0; m < 4; ++m) corner[m] = at(static_cast<std::size_t>(cell[m]));
  const std::size_t count = points.size() / 3;
  for (std::size_t i = 0; i < count; ++i) {
    if (exempt[i]) continue;
    if (CGAL::side_of_bounded_sphere(corner[0], corner[1], corner[2], corner[3], at(i)) !=
        CGAL::ON_UNBOUNDED_SIDE) {
      return false;
    }
  }
  return true;
}

}  // namespace brdf::interp
