// The search index of the fast octant and nearest-neighbour methods: a k-d tree over a
// PointCloud's scaled coordinates. One traversal finds the nearest point in every orthant around
// the query at once (the octant method's step 2): nearer child first, a subtree pruned when, for
// every orthant its box reaches, its lower-bound distance already exceeds that orthant's best.
//
// Exactness: the bounds are computed with rounded operations that never exceed the computed
// distance of a point in the box, then shrunk by a relative 1e-12, so pruning never drops a point
// the brute-force scan would pick. Every kernel computes a point's distance with SquaredDistance's
// operations in SquaredDistance's order (no fused multiply-add), and ties go to the lower rank:
// results, ties included, are identical to the O(N) scan of octant/reference.h.
//
// Speed: the points live in tree order as one array per axis, so a leaf is scanned several points
// per instruction. A leaf kernel (chosen once, from what the CPU supports) computes distances and
// orthants for 8 (AVX-512) or 4 (AVX2) points at a time, compares each with its orthant's best
// held in registers (permuted into place: no gather), and sends through the exact rule only the
// rare point below that best, or at it but not that very point (a seed met again in its leaf).
// The 4D AVX2 kernel gathers the bests instead (16 would take 8 registers: spilled, no faster)
// and sends every point at or below its best. A portable scalar kernel does the
// same without branches. Pruning compares a box's distance with every orthant's best at once (one
// vector compare) and keeps the orthants the box reaches (a table indexed by which sides of the
// query the box spans). On CPUs with AVX2 the walk is iterative (an explicit stack, nearer child
// first as in the recursion) and computes a box's distance and sides for all axes in one register.
// The walk (hard-to-predict visits) still costs about as much as the leaf scans (perf on a sorted
// batch over 50,000 random points, 2026-12-02: walk 14 %, leaves 13 % of all samples).
//
// Shortcut (Search::kGridThenTree, opt-in): an OrthantGrid (search/orthant_grid.h) lists, for each
// cell of a uniform grid, every point that can win an orthant for some query in the cell; a query
// whose cell has a list scans it and skips the tree. The list kernels (AVX-512, AVX2: 8 or 4
// entries at a time, coordinates gathered from the per-axis arrays by tree position, bests in
// registers; scalar) use the leaf kernels' arithmetic and stop at the first block of entries that
// cannot beat the needed orthants' bests. Queries outside the grid, and cells the grid could not
// bound, walk the tree. Same answers either way.
// Pure: no I/O.
#pragma once

#include <array>
#include <cstdint>
#include <span>
#include <vector>

#include "core/interp/octant/cube.h"
#include "core/interp/search/orthant_grid.h"
#include "core/interp/search/point_cloud.h"

namespace brdf::interp {

class KdTree {
 public:
  // How leaves are scanned. kBest picks the fastest the CPU supports; the others are for tests and
  // benchmarks (a kernel the CPU lacks falls back to kScalar). All give identical results.
  enum class Kernel { kBest, kScalar, kAvx2, kAvx512 };

  // How NearestPerOrthant searches: the tree alone, or the grid's list first (see above). On the
  // rig grid the grid makes the search 2–3× faster (AVX2: about 0.45 against 1.2 µs), but tree +
  // grid take about 100× the tree's build time (about 0.14 s; bench/README.md has the figures),
  // so it is opt-in here;
  // OctantInterpolator::Create opts in, its Extend's folds do not (octant/octant.h). Only 3D clouds
  // of at most OrthantGrid::Options::max_points points get a grid.
  enum class Search { kTree, kGridThenTree };

  // Indexes the cloud's scaled points (3D or 4D, at least one). Keeps a pointer to `cloud`, which
  // must outlive the tree and not change.
  explicit KdTree(const PointCloud& cloud, Kernel kernel = Kernel::kBest,
                  Search search = Search::kTree);

  int dims() const { return dims_; }
  // The kernel in use (never kBest) and its name ("avx512", "avx2", "scalar").
  Kernel kernel() const { return kernel_; }
  static const char* KernelName(Kernel kernel);
  // True when this CPU can run `kernel`.
  static bool Supported(Kernel kernel);

  // For every orthant o around p (scaled space, OrthantOf numbering): the rank of the point nearest
  // to p in o, the lowest rank among points at the same distance, or kNoPoint when o holds no
  // point; and a pointer to its scaled coordinates in the cloud. p must be finite.
  void NearestPerOrthant(const double* p, OrthantWinners& winners) const;

  // The rank of the point nearest to p (the lowest rank among equals). p must be finite.
  std::uint32_t Nearest(const double* p) const;

  // True when p lies outside the points' bounding box on some axis j (p_j <= min_j: no point on
  // the − side, or p_j > max_j: none on the + side), so that some orthant around p is certainly
  // empty: NearestPerOrthant would report kNoPoint there. p must be finite.
  bool OutsideBox(const double* p) const;

  // Batches (OctantInterpolator::SpectraAt) group their queries by grid cell, because the queries
  // of one cell can share one scan of its list. ListedCell is p's cell (OrthantGrid::kNoCell when p
  // is outside the grid or its cell has no list: search those with NearestPerOrthant).
  // NearestPerOrthantInCell answers `count` (1 … kCellLanes) queries of one such cell at once,
  // each as the cube of winners the vector blends read (octant/cube.h, WinnerCube3):
  // with AVX-512, one query per vector lane, the list's entries broadcast to all lanes, no
  // branch per entry (the kernel in search/kd_tree_cells.cc); elsewhere, and for a lone query, one
  // list scan per query. The winners are NearestPerOrthant's, bit for bit, ties included.
  static constexpr int kCellLanes = 8;
  std::uint32_t ListedCell(const double* p) const;
  // Without a grid, batches still sort their queries by the cell of the coarse seed grid (about
  // two points per cell, search/kd_tree.cc): consecutive queries then walk the same part of the
  // tree and read the same points. SeedCell(p) < seed_cell_count(); p must be finite.
  std::uint32_t SeedCell(const double* p) const;
  std::size_t seed_cell_count() const { return seeds_.size() >> dims_; }
  void NearestPerOrthantInCell(std::uint32_t cell, const double* const* queries, int count,
                               WinnerCube3* cubes) const;

  // Heap of the tree, its seeds and its grid shortcut (not the cloud's, which it points into).
  std::size_t HeapBytes() const;
  // Nodes in the tree and points per leaf (for benchmarks).
  std::size_t node_count() const { return nodes_.size(); }
  std::uint32_t leaf_size() const { return leaf_size_; }
  // The grid shortcut (empty with Search::kTree).
  const OrthantGrid& grid() const { return grid_; }

  // The search state of one NearestPerOrthant call (public for the kernels in search/kd_tree.cc).
  struct OrthantBest;
  // Points a leaf kernel scans: one array per axis and their ranks.
  struct Entries {
    const double* axis[4];
    const std::uint32_t* rank;
  };

 private:
  struct Node {
    std::array<double, 4> lo;  // tight bounding box of the node's points
    std::array<double, 4> hi;
    std::uint32_t begin;  // the node's points: positions [begin, end) in tree order
    std::uint32_t end;
    std::uint32_t right;  // right child (left child is the next node); 0 for a leaf
    std::uint32_t axis;   // split axis
    double split;         // points left have coordinate <= split, right >= split
  };
  struct NearestBest;
  // Scans positions [begin, end) of a leaf into `best`; true when some orthant improved.
  using LeafScan = bool (*)(const Entries& entries, std::uint32_t begin, std::uint32_t end,
                            OrthantBest& best);
  // Scans `blocks` blocks of 8 tree positions of a grid list (see OrthantGrid).
  using ListScan = void (*)(const KdTree& tree, const std::uint32_t* entry, const double* block_gap,
                            std::uint32_t blocks, unsigned need, OrthantBest& best);

  std::uint32_t Build(std::vector<std::uint32_t>& order, std::uint32_t begin, std::uint32_t end);
  void BuildSeeds();
  void Seed(OrthantBest& best) const;
  template <int D>
  void VisitOrthants(std::uint32_t node, OrthantBest& best) const;
  template <int D>
  void VisitOrthantsAvx2(std::uint32_t node, OrthantBest& best) const;
  template <int D>
  void SearchOrthants(OrthantBest& best, OrthantWinners& winners) const;
  // The winners at tree positions pos[o] (kNoPoint: orthant o is empty).
  template <int D>
  void FillWinners(const std::uint32_t* pos, OrthantWinners& winners) const;
  template <int D>
  void VisitNearest(std::uint32_t node, const double* p, NearestBest& best) const;
  template <int D>
  friend struct LeafKernels;

  const PointCloud* cloud_;
  int dims_;
  Kernel kernel_;
  LeafScan scan_;
  ListScan list_scan_;
  std::uint32_t leaf_size_;
  std::vector<Node> nodes_;
  // Scaled coordinates in tree order, one array per axis, padded with kPadding copies of the
  // last point so that vector loads past a leaf's end stay inside the array.
  std::array<std::vector<double>, 4> axis_;
  std::vector<std::uint32_t> rank_;  // tree position → rank in the cloud (padded with kNoPoint)
  // Seeds: a coarse grid over the points' bounding box, and for each cell the tree positions of
  // the winners at the cell's centre (kNoPoint where none). A query first offers its cell's seeds,
  // real points near its own winners, so that from the first leaf on only points that beat them
  // go through the exact update (the answer cannot change: every point is still considered).
  int seed_cells_ = 0;  // cells per axis
  std::array<double, 4> seed_lo_{};
  std::array<double, 4> seed_inv_{};  // cells per unit of each axis
  std::vector<std::uint32_t> seeds_;
  OrthantGrid grid_;
};

}  // namespace brdf::interp
