// The kernel behind KdTree::NearestPerOrthantInCell (search/kd_tree.h): one scan of a grid cell's
// list for up to kCellLanes queries of that cell, one query per vector lane. Internal to the k-d
// tree; search/kd_tree_cells.cc says how it works and why it gives the exact winners. Pure: no I/O.
#pragma once

#include <cstddef>
#include <cstdint>

#include "core/interp/octant/cube.h"

namespace brdf::interp {

inline constexpr int kCellLanes = 8;

// Orthant o of `cube`: the winner at tree position `pos` (its coordinates from the per-axis
// arrays, its rank), or empty when pos is kNoPoint. For kernels that end with positions.
inline void PutCubeWinner(const double* const* axis, const std::uint32_t* rank, std::uint32_t pos,
                          std::size_t o, WinnerCube3& cube) {
  if (pos == kNoPoint) {
    cube.empty |= 1u << o;
    return;
  }
  cube.rank[o] = rank[pos];
  for (std::size_t j = 0; j < 3; ++j) cube.axis[j][o] = axis[j][pos];
}

#if defined(__x86_64__) && (defined(__GNUC__) || defined(__clang__))
// Scans a 3D cell's list (entries: tree positions, 8 per block; block_gap: per block, a lower
// bound on its entries' squared distance from any query of the cell; need: the orthants that can
// hold a point for a query of the cell) for queries[0 … count), 1 <= count <= kCellLanes, scaled
// coordinates. axis: the tree's per-axis coordinate arrays and rank: its ranks, by tree position.
// cubes[k]: query k's winners (their ranks are the tree's, `rank[position]`).
// Needs AVX-512F (KdTree only calls it when its kernel is kAvx512).
void CellListAvx512(const double* const* axis, const std::uint32_t* rank,
                    const std::uint32_t* entry, const double* block_gap, std::uint32_t blocks,
                    unsigned need, const double* const* queries, int count, WinnerCube3* cubes);

// The same with AVX2, for 1 <= count <= kCellLanesAvx2 queries, whose tree positions must be below
// kCellAvx2Positions (the kernel packs a position into the low bits of a distance).
inline constexpr int kCellLanesAvx2 = 4;
inline constexpr std::uint32_t kCellAvx2Positions = 1u << 14;
void CellListAvx2(const double* const* axis, const std::uint32_t* rank, const std::uint32_t* entry,
                  const double* block_gap, std::uint32_t blocks, unsigned need,
                  const double* const* queries, int count, WinnerCube3* cubes);
#endif

}  // namespace brdf::interp
