// The k-d tree's opt-in shortcut for the octant method's search (search/kd_tree.h, Search::
// kGridThenTree): a uniform grid of cells over the scaled points' bounding box that lists, for
// each cell, every point that can be the nearest in some orthant around SOME query inside the
// cell. A query finds its cell and scans one short list (tree positions, whose coordinates the
// k-d tree's list kernels gather from its compact per-axis arrays) instead of walking the tree.
//
// Why a list is complete. Take cell B = [lo, hi] and orthant o. Its near corner n (hi_j on the
// axes where o is +, lo_j where o is −) and far corner f (the opposite one) are grid vertices. A
// point w in orthant o of n ("witness") is in orthant o of every query q in B, and
// |q − w| <= |f − w|. So a point p can win o for some q in B only if (1) it can lie in o for some
// q in B, (2) mindist(B, p) <= U = min over witnesses of |f − w|, and (3) for every witness w,
// |q − p| <= |q − w| for some q in B (a linear condition in q: checked at one corner). The list
// is the union over the orthants of the points that pass. An orthant empty at f is empty for
// every query in B (no candidates); one empty at n but not at f (an edge or a hole of the data:
// no witness) gets all the points that can lie in it for some q in B, when they are few.
// Distances are compared with relative margins of 1e-9, far above the rounding of the sums (a few
// ulps), so rounding can only add candidates, never drop one: a scan of the list finds exactly
// the winners, ties included, that the O(N) scan finds.
//
// A list is sorted by each entry's distance bound from the cell, so the scan stops at the first
// block of 8 entries whose bound exceeds every needed orthant's best (orthant_grid_test.cc).
// Cells whose list would be too long or reach too far keep none, and the tree answers their
// queries, as it does for queries outside the grid. The grid's box starts just above the points'
// minimum on every axis, so that the points on the data's lower faces lie in the − orthants of
// the whole first layer of cells. 3D only (see the constructor). Pure: no I/O.
#pragma once

#include <array>
#include <cstddef>
#include <cstdint>
#include <functional>
#include <span>
#include <vector>

#include "core/interp/octant/cube.h"
#include "core/interp/search/point_cloud.h"

namespace brdf::interp {

class OrthantGrid {
 public:
  struct Options {
    // Cells per point of the cloud: smaller cells mean shorter lists but more of them (memory and
    // build time). Measured with bench/ on the rig grid and 50,000 random points.
    double cells_per_point = 4.0;
    // Longest list kept; a cell that needs more falls back to the tree.
    std::uint32_t max_list = 192;
    // A cell whose bound reaches farther than this many cell widths keeps no list (the build's
    // enumeration would cost more than the list could save). On the rig grid 16 left 22 % of
    // the cells without a list, near the data's edges, where the tree is slowest (an empty
    // orthant cannot be pruned); 64 lists 99.6 % of them for 1.4× the build time.
    double max_reach = 64.0;
    // Larger clouds get no grid: the build would take seconds. Measured with the AVX2 list
    // kernel on 50,000 random points (bench/README.md): the search got about 25 % faster
    // (grid then tree about 1.65 µs against 2.0–2.3 µs for the tree alone, 77–81 % of the queries
    // answered by a list) but the build took 1.35 s at 0.5 cells per point, 1.8 s at 1 and 5.4 s
    // (38 MB) at 4, beyond the ~0.5 s a session's index may take; so the limit stays.
    std::size_t max_points = 16384;
    // Upper bound on the number of cells (memory), whatever cells_per_point asks for.
    std::size_t max_cells = std::size_t{1} << 22;
  };

  // No grid: every query falls back.
  OrthantGrid() = default;
  // Builds the lists for a 3D cloud's scaled points (a 4D cloud gets no grid: with 16 orthants
  // few cells kept a list short enough; nor does a cloud flat on an axis, up to rounding: an
  // extent under 1e-9 of the widest). A list entry is the point's position in the caller's
  // order, position_of[rank] (the k-d tree's own order, whose compact per-axis arrays stay in
  // cache while the lists are read). Keeps no pointer to its arguments.
  // `search` finds the exact winners per orthant around a point (the tree's NearestPerOrthant):
  // the witnesses are the winners at the grid's vertices.
  using Search = std::function<void(const double* p, OrthantWinners& winners)>;
  OrthantGrid(const PointCloud& cloud, const std::vector<std::uint32_t>& position_of,
              const Search& search)
      : OrthantGrid(cloud, position_of, search, Options{}) {}
  OrthantGrid(const PointCloud& cloud, const std::vector<std::uint32_t>& position_of,
              const Search& search, const Options& options);

  bool empty() const { return cells_ == 0; }
  int dims() const { return dims_; }

  // The candidates of q's cell: list entries [begin, begin + count), begin and count multiples
  // of 8 (a list is padded with copies of its last entry, which can never change a winner). False
  // when q is outside the grid or its cell has no list (the caller must search another way).
  // q must be finite.
  // `need`: the orthants that can hold a point for some query of the cell (bit o for orthant o);
  // the others are empty for every query of the cell.
  template <int D>
  bool Find(const double* q, std::uint32_t& begin, std::uint32_t& count,
            std::uint32_t& need) const {
    const std::uint32_t cell = ListedCell<D>(q);
    if (cell == kNoCell) return false;
    List(cell, begin, count, need);
    return true;
  }

  // Find in two steps, for batches that group their queries by cell: the cell whose list answers
  // q (kNoCell when q is outside the grid or its cell has no list), then that cell's list.
  static constexpr std::uint32_t kNoCell = 0xFFFFFFFFu;
  template <int D>
  std::uint32_t ListedCell(const double* q) const {
    std::size_t cell = 0;
#pragma GCC unroll 4
    for (int j = 0; j < D; ++j) {
      const auto uj = static_cast<std::size_t>(j);
      const double f = (q[j] - lo_[uj]) * inv_[uj];
      if (!(f >= 0.0 && f < static_cast<double>(count_[uj]))) return kNoCell;
      const auto k = static_cast<std::size_t>(f);
      // The division above can round across a line: the lines themselves decide.
      const double* line = lines_[uj].data() + k;
      if (q[j] < line[0] || q[j] >= line[1]) return kNoCell;
      cell = cell * static_cast<std::size_t>(count_[uj]) + k;
    }
    return span_[cell].count == kNoList ? kNoCell : static_cast<std::uint32_t>(cell);
  }
  void List(std::uint32_t cell, std::uint32_t& begin, std::uint32_t& count,
            std::uint32_t& need) const {
    const Span s = span_[cell];
    begin = s.begin;
    count = s.count;
    need = s.need;
  }

  // The list entries: positions (see the constructor), each list nearest to its cell first.
  const std::uint32_t* entry() const {
    return entry_.data();
  }
  // Per block of 8 entries (entry index / 8): a lower bound on the squared distance of the
  // block's entries from any query of its cell, rounding included. Once it exceeds the best
  // squared distance of every needed orthant, no entry from that block on can win or tie.
  const double* block_gap() const {
    return block_gap_.data();
  }

  // For benchmarks and reports.
  std::size_t cell_count() const {
    return cells_;
  }
  std::size_t listed_cells() const {
    return listed_cells_;
  }
  std::size_t entries() const {
    return entry_.size();
  }
  std::size_t bytes() const;
  // Cells without a list: [0] an orthant empty at the near corner but not at the far one (a hole
  // or an edge of the data), [1] the bound reaches too far, [2] the list would be too long.
  std::array<std::size_t, 3> unlisted() const {
    return unlisted_;
  }
  std::array<int, 4> cells_per_axis() const {
    return count_;
  }
  // The cell boundaries of axis j: cells_per_axis()[j] + 1 values, increasing (for tests).
  std::span<const double> lines(int j) const {
    const auto& l = lines_[static_cast<std::size_t>(j)];
    return l.empty() ? std::span<const double>() : std::span<const double>(l.data(), l.size() - 1);
  }

 private:
  static constexpr std::uint32_t kNoList = 0xFFFFFFFFu;
  struct Span {
    std::uint32_t begin = 0;
    std::uint32_t count = kNoList;
    std::uint32_t need = 0;
  };
  // Builds the lists (search/orthant_grid.cc): the box, the points in buckets, then cell by cell.
  template <int D>
  class Builder;

  int dims_ = 0;
  std::size_t cells_ = 0;
  std::size_t listed_cells_ = 0;
  std::array<std::size_t, 3> unlisted_{};
  std::array<int, 4> count_{};  // cells per axis
  std::array<double, 4> lo_{};
  std::array<double, 4> inv_{};               // cells per unit of each axis
  std::array<std::vector<double>, 4> lines_;  // per axis: count_ + 2 cell boundaries (last: +inf)
  std::vector<Span> span_;                    // per cell, row-major (last axis fastest)
  std::vector<std::uint32_t> entry_;
  std::vector<double> block_gap_;
};

}  // namespace brdf::interp
