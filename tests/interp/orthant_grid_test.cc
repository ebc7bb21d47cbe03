// The k-d tree's grid shortcut (core/interp/search/orthant_grid.h, KdTree::Search::kGridThenTree)
// against an O(N) scan written here: the winners of every orthant, ties to the lower rank, must be
// the scan's on data full of ties, duplicates and points on the cell lines, for queries on the cell
// lines, inside and outside the grid, in 3D and 4D, with symmetry copies, for every kernel; and the
// grid must actually answer queries (a shortcut that always fell back would pass the exactness
// checks and be useless).
#include "core/interp/search/orthant_grid.h"

#include <gtest/gtest.h>

#include <cstdint>
#include <limits>
#include <string>
#include <vector>

#include "core/interp/octant/cube.h"
#include "core/interp/search/kd_tree.h"
#include "core/interp/search/point_cloud.h"
#include "interp_test_data.h"

namespace brdf::interp {
namespace {

using testing::Lattice;
using testing::LinearSpectrum;
using testing::MakeSamples;
using testing::PaperGrid;
using testing::Point;
using testing::RandomPoints;

// The winners by definition: nearest (SquaredDistance) in each orthant (OrthantOf), ties to the
// lower rank.
void ScanWinners(const PointCloud& cloud, const double* p, std::vector<std::uint32_t>& rank) {
  const int d = cloud.dims;
  rank.assign(std::size_t{1} << d, kNoPoint);
  std::vector<double> best(rank.size(), std::numeric_limits<double>::infinity());
  for (std::size_t r = 0; r < cloud.size(); ++r) {
    const double* x = cloud.scaled_point(r).data();
    const auto o = static_cast<std::size_t>(OrthantOf(x, p, d));
    const double d2 = SquaredDistance(x, p, d);
    if (d2 < best[o]) {  // ranks ascend: the first at a distance keeps it
      best[o] = d2;
      rank[o] = static_cast<std::uint32_t>(r);
    }
  }
}

// Queries that stress the grid: on its cell lines (every axis, alternately), at the data's
// points (on the cells' edges of the lattices), just outside the grid, and random ones.
std::vector<Point> StressQueries(const OrthantGrid& grid, const std::vector<Point>& points,
                                 const std::vector<double>& lo, const std::vector<double>& hi,
                                 std::uint64_t seed) {
  const std::size_t d = lo.size();
  std::vector<Point> queries = RandomPoints(300, lo, hi, seed);
  const std::vector<Point> base = RandomPoints(300, lo, hi, seed + 1);
  for (std::size_t i = 0; i < base.size(); ++i) {
    Point q = base[i];
    for (std::size_t j = 0; j < d; ++j) {
      const auto lines = grid.lines(static_cast<int>(j));
      if (lines.empty() || (i + j) % 2 != 0) continue;
      q[j] = lines[(i * 7 + j) % lines.size()];
    }
    queries.push_back(q);
  }
  for (std::size_t i = 0; i < points.size(); i += std::max<std::size_t>(1, points.size() / 150)) {
    queries.push_back(points[i]);
  }
  for (std::size_t j = 0; j < d; ++j) {
    const auto lines = grid.lines(static_cast<int>(j));
    if (lines.empty()) continue;
    Point below = base[j], above = base[j + 1];
    below[j] = lines.front();
    queries.push_back(below);
    below[j] = std::nextafter(lines.front(), -1e300);
    queries.push_back(below);
    above[j] = lines.back();
    queries.push_back(above);
    above[j] = std::nextafter(lines.back(), 1e300);
    queries.push_back(above);
  }
  return queries;
}

struct Case {
  std::string name;
  std::vector<Point> points;
  std::vector<double> lo, hi;  // the query box (a little wider than the data)
  Options options;
  // The share of the queries the grid must answer itself. 4D clouds get no grid
  // (core/interp/search/orthant_grid.cc says why): the tree answers everything, and must still be
  // exact.
  double min_share = 0.1;
};

std::vector<Case> Cases() {
  std::vector<Case> cases;
  cases.push_back({"paper grid", PaperGrid(), {-5, -5, -5}, {95, 95, 185}, {}});
  Options mirror;
  mirror.mirror_phi = true;
  mirror.reciprocity = true;
  cases.push_back(
      {"paper grid, mirror_phi + reciprocity", PaperGrid(), {-5, -5, -185}, {95, 95, 185}, mirror});
  cases.push_back({"random 3D",
                   RandomPoints(3000, {0, 0, 0}, {90, 90, 360}, 31),
                   {-5, -5, -5},
                   {95, 95, 365},
                   {}});
  // Ties everywhere, 3 copies of every point, points on the cell lines.
  std::vector<Point> lattice;
  for (int copy = 0; copy < 3; ++copy) {
    for (const Point& p : Lattice(3, 9)) lattice.push_back(p);
  }
  cases.push_back({"lattice with duplicates", lattice, {-1, -1, -1}, {9, 9, 9}, {}});
  Options scaled;
  scaled.axis_scale = {1.0, 2.0, 0.25};
  cases.push_back({"lattice, axis_scale", Lattice(3, 8), {-1, -1, -1}, {8, 8, 8}, scaled});
  cases.push_back({"random 4D",
                   RandomPoints(2000, {0, 0, 0, 0}, {90, 360, 90, 360}, 32),
                   {-5, -5, -5, -5},
                   {95, 365, 95, 365},
                   {},
                   0.0});
  cases.push_back({"4D lattice", Lattice(4, 5), {-1, -1, -1, -1}, {5, 5, 5, 5}, {}, 0.0});
  return cases;
}

TEST(OrthantGridTest, WinnersAreTheScansForEveryKernel) {
  for (const Case& c : Cases()) {
    SCOPED_TRACE(c.name);
    const int dims = static_cast<int>(c.points[0].size());
    const auto samples = MakeSamples(c.points, LinearSpectrum(dims, 1));
    const PointCloud cloud = BuildPointCloud(*samples, c.options).value();
    const KdTree probe(cloud, KdTree::Kernel::kBest, KdTree::Search::kGridThenTree);
    ASSERT_EQ(probe.grid().empty(), dims == 4);
    // Queries in the cloud's scaled space (StressQueries uses the grid's lines, which are).
    std::vector<double> lo = c.lo, hi = c.hi;
    for (std::size_t j = 0; j < lo.size(); ++j) {
      lo[j] *= cloud.scale[j];
      hi[j] *= cloud.scale[j];
    }
    std::vector<Point> scaled_points;
    for (std::size_t r = 0; r < cloud.size(); ++r) {
      const auto p = cloud.scaled_point(r);
      scaled_points.emplace_back(p.begin(), p.end());
    }
    const std::vector<Point> queries = StressQueries(probe.grid(), scaled_points, lo, hi, 40);
    ASSERT_GT(queries.size(), 600u);
    for (KdTree::Kernel kernel :
         {KdTree::Kernel::kScalar, KdTree::Kernel::kAvx2, KdTree::Kernel::kAvx512}) {
      if (!KdTree::Supported(kernel)) continue;
      SCOPED_TRACE(KdTree::KernelName(kernel));
      const KdTree tree(cloud, kernel, KdTree::Search::kGridThenTree);
      std::size_t answered_by_grid = 0;
      for (const Point& q : queries) {
        std::uint32_t begin = 0, count = 0, need = 0;
        answered_by_grid += dims == 3 ? tree.grid().Find<3>(q.data(), begin, count, need)
                                      : tree.grid().Find<4>(q.data(), begin, count, need);
        OrthantWinners got;
        std::vector<std::uint32_t> want;
        tree.NearestPerOrthant(q.data(), got);
        ScanWinners(cloud, q.data(), want);
        for (std::size_t o = 0; o < want.size(); ++o) {
          ASSERT_EQ(got.rank[o], want[o])
              << "orthant " << o << " of query " << q[0] << ", " << q[1] << ", " << q[2];
          if (want[o] == kNoPoint) continue;
          const auto p = cloud.scaled_point(want[o]);
          EXPECT_EQ(std::vector<double>(got.scaled[o], got.scaled[o] + dims),
                    std::vector<double>(p.begin(), p.end()));
        }
      }
      // The shortcut is used, not only the fallback.
      if (c.min_share > 0) {
        EXPECT_GT(static_cast<double>(answered_by_grid),
                  c.min_share * static_cast<double>(queries.size()));
      } else {
        EXPECT_EQ(answered_by_grid, 0u);
      }
    }
  }
}

TEST(OrthantGridTest, CellsWithoutAListFallBackToTheTree) {
  // Tiny lists: most cells keep none, and their queries must get the tree's (the scan's) answer.
  const std::vector<Point> points = RandomPoints(1500, {0, 0, 0}, {90, 90, 360}, 33);
  const auto samples = MakeSamples(points, LinearSpectrum(3, 1));
  const PointCloud cloud = BuildPointCloud(*samples, {}).value();
  std::vector<std::uint32_t> identity(cloud.size());
  for (std::uint32_t r = 0; r < identity.size(); ++r) identity[r] = r;
  const KdTree tree(cloud);
  const auto search = [&tree](const double* p, OrthantWinners& w) { tree.NearestPerOrthant(p, w); };
  OrthantGrid::Options options;
  options.max_list = 16;
  const OrthantGrid small(cloud, identity, search, options);
  EXPECT_LT(small.listed_cells(), small.cell_count());
  const OrthantGrid normal(cloud, identity, search);
  EXPECT_GT(normal.listed_cells(), small.listed_cells());
  EXPECT_GT(normal.listed_cells(), normal.cell_count() / 2);
  // Every listed cell's list is whole blocks of 8 positions of real points.
  for (std::size_t e = 0; e < normal.entries(); ++e) ASSERT_LT(normal.entry()[e], cloud.size());
  EXPECT_EQ(normal.entries() % 8, 0u);
}

TEST(OrthantGridTest, DegenerateCloudsHaveNoGridAndStillAnswer) {
  // All points in one plane (no extent on an axis), in one plane up to rounding (±1e-15 on an
  // axis, as half/difference points of in-plane readings are: such an axis once made the other
  // two max_cells wide, a build of seconds), and a single point: no grid, tree answers.
  std::vector<Point> flat, nearly_flat;
  for (int k = 0; k < 200; ++k) {
    flat.push_back({1.0 * (k % 20), 2.0 * (k / 20), 5.0});
    nearly_flat.push_back({1.0 * (k % 20), 2.0 * (k / 20), 5.0 + (k % 3 - 1) * 1e-15});
  }
  for (const std::vector<Point>& points : {flat, nearly_flat, std::vector<Point>{{1, 2, 3}}}) {
    const auto samples = MakeSamples(points, LinearSpectrum(3, 1));
    const PointCloud cloud = BuildPointCloud(*samples, {}).value();
    const KdTree tree(cloud, KdTree::Kernel::kBest, KdTree::Search::kGridThenTree);
    EXPECT_TRUE(tree.grid().empty());
    for (const Point& q : RandomPoints(200, {-1, -1, 4}, {21, 21, 6}, 34)) {
      OrthantWinners got;
      std::vector<std::uint32_t> want;
      tree.NearestPerOrthant(q.data(), got);
      ScanWinners(cloud, q.data(), want);
      for (std::size_t o = 0; o < want.size(); ++o) ASSERT_EQ(got.rank[o], want[o]);
    }
  }
}

TEST(OrthantGridTest, TheTreeAloneBuildsNoGrid) {
  const auto samples =
      MakeSamples(RandomPoints(500, {0, 0, 0}, {1, 1, 1}, 35), LinearSpectrum(3, 1));
  const PointCloud cloud = BuildPointCloud(*samples, {}).value();
  EXPECT_TRUE(KdTree(cloud).grid().empty());
  EXPECT_FALSE(KdTree(cloud, KdTree::Kernel::kBest, KdTree::Search::kGridThenTree).grid().empty());
}

}  // namespace
}  // namespace brdf::interp
