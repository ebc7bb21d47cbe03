// The allocation-free paths of the octant and nearest methods, and the k-d tree's leaf kernels:
// OctantInterpolator::EvaluateInto and SpectrumAt give Evaluate's numbers bit for bit (status,
// vertices, weights, spectrum), and every leaf kernel the CPU supports (scalar, AVX2, AVX-512)
// finds the same winners as a brute-force scan written here, ties and duplicates included.
// FindOctantBlendFast (the five tetrahedra at once) gives FindOctantBlend's blend bit for bit.
#include <gtest/gtest.h>

#include <bit>
#include <cmath>
#include <cstring>
#include <limits>
#include <map>
#include <random>
#include <span>

#include "core/interp/nearest.h"
#include "core/interp/octant/cube.h"
#include "core/interp/octant/octant.h"
#include "core/interp/search/kd_tree.h"
#include "core/interp/search/point_cloud.h"
#include "interp_test_data.h"

namespace brdf::interp {
namespace {

using testing::AnalyticSpectrum;
using testing::Lattice;
using testing::LinearSpectrum;
using testing::MakeSamples;
using testing::PaperGrid;
using testing::Point;
using testing::RandomPoints;

void ExpectIntoMatchesEvaluate(const OctantInterpolator& interp, const Point& q) {
  SCOPED_TRACE(::testing::Message() << "query " << q[0] << ", " << q[1] << ", " << q[2]);
  const Interpolation full = interp.Evaluate(q);
  std::vector<double> spectrum(static_cast<std::size_t>(interp.bands()), -7.0);
  const OctantResult r = interp.EvaluateInto(q, spectrum);
  ASSERT_EQ(r.status, full.status);
  std::vector<double> fast(static_cast<std::size_t>(interp.bands()), -7.0);
  EXPECT_EQ(interp.SpectrumAt(q, fast), full.status);
  if (full.status != InterpStatus::kOk) {
    EXPECT_EQ(r.vertex_count, 0);
    EXPECT_NE(r.empty_orthants != 0, full.status == InterpStatus::kNoEnclosingSimplex);
    EXPECT_EQ(spectrum, std::vector<double>(spectrum.size(), -7.0));  // untouched
    EXPECT_EQ(fast, spectrum);
    return;
  }
  EXPECT_EQ(spectrum, full.spectrum);
  EXPECT_EQ(fast, full.spectrum);
  ASSERT_EQ(static_cast<std::size_t>(r.vertex_count), full.vertices.size());
  for (std::size_t k = 0; k < full.vertices.size(); ++k) {
    EXPECT_EQ(r.index[k], full.vertices[k].index);
    EXPECT_EQ(r.weight[k], full.vertices[k].weight);
  }
  EXPECT_EQ(SimplexName(r.simplex, interp.dims()), full.detail);
}

TEST(OctantFastPathTest, EvaluateIntoAndSpectrumAtAreEvaluateBitForBit) {
  const auto grid = PaperGrid();
  const auto samples = MakeSamples(grid, AnalyticSpectrum(3));
  for (const Options& options : {Options{}, Options{{1, 1, 0.5}, true, true}}) {
    auto interp = OctantInterpolator::Create(samples, options);
    ASSERT_TRUE(interp.ok()) << interp.status().ToString();
    for (const Point& q : RandomPoints(3000, {-5, -5, -5}, {95, 95, 185}, 11)) {
      ExpectIntoMatchesEvaluate(**interp, q);
    }
    for (std::size_t i = 0; i < grid.size(); i += 7) ExpectIntoMatchesEvaluate(**interp, grid[i]);
  }
  // 4D.
  const auto points4 = RandomPoints(1500, {0, 0, 0, 0}, {90, 360, 90, 360}, 12);
  auto interp4 = OctantInterpolator::Create(MakeSamples(points4, LinearSpectrum(4, 6))).value();
  for (const Point& q : RandomPoints(1500, {0, 0, 0, 0}, {90, 360, 90, 360}, 13)) {
    const Interpolation full = interp4->Evaluate(q);
    std::vector<double> spectrum(6);
    const OctantResult r = interp4->EvaluateInto(q, spectrum);
    ASSERT_EQ(r.status, full.status);
    if (r.status == InterpStatus::kOk) {
      EXPECT_EQ(spectrum, full.spectrum);
      EXPECT_EQ(r.vertex_count, 5);
      for (std::size_t k = 0; k < 5; ++k) EXPECT_EQ(r.weight[k], full.vertices[k].weight);
    }
  }
}

TEST(OctantFastPathTest, EmptyOrthantsAndInvalidQueriesAreReported) {
  const auto samples = MakeSamples(Lattice(3, 4), LinearSpectrum(3, 2));
  auto interp = OctantInterpolator::Create(samples).value();
  std::vector<double> spectrum(2, -1.0);
  // Below every sample on θi: the (θi−) octants A, D, E, H (0, 2, 4, 6) are empty.
  const OctantResult below = interp->EvaluateInto(Point{-1, 1.5, 1.5}, spectrum);
  EXPECT_EQ(below.status, InterpStatus::kEmptyOctant);
  EXPECT_EQ(below.empty_orthants, 0b01010101u);
  const OctantResult nan = interp->EvaluateInto(Point{1, NAN, 1}, spectrum);
  EXPECT_EQ(nan.status, InterpStatus::kEmptyOctant);
  EXPECT_EQ(nan.empty_orthants, 0xFFu);
  EXPECT_EQ(interp->EvaluateInto(Point{1, 1}, spectrum).status, InterpStatus::kEmptyOctant);
  EXPECT_EQ(spectrum, std::vector<double>(2, -1.0));
  // A short buffer gets the first bands only.
  std::vector<double> one(1, -1.0);
  EXPECT_EQ(interp->SpectrumAt(Point{1.5, 1.5, 1.5}, one), InterpStatus::kOk);
  EXPECT_EQ(one[0], interp->Evaluate(Point{1.5, 1.5, 1.5}).spectrum[0]);
}

TEST(OctantFastPathTest, SpectraAtIsSpectrumAtQueryByQuery) {
  // The pipelined batch (octant) and the interface's default loop (nearest) against SpectrumAt,
  // with failures (NaN rows) between successes and an invalid query in the middle.
  const auto samples = MakeSamples(PaperGrid(), AnalyticSpectrum(3));
  auto queries = RandomPoints(2000, {-5, -5, -5}, {95, 95, 185}, 31);
  queries[1000] = {1, NAN, 1};
  std::vector<double> flat;
  for (const Point& q : queries) flat.insert(flat.end(), q.begin(), q.end());
  const auto bands = static_cast<std::size_t>(samples->bands());
  std::vector<std::unique_ptr<Interpolator>> interps;
  interps.push_back(OctantInterpolator::Create(samples).value());
  interps.push_back(MakeNearestInterpolator(samples).value());
  for (const auto& interp : interps) {
    SCOPED_TRACE(MethodName(interp->method()));
    std::vector<InterpStatus> status(queries.size());
    std::vector<double> spectra(queries.size() * bands, -3.0);
    interp->SpectraAt(flat, status, spectra);
    std::size_t failed = 0;
    for (std::size_t i = 0; i < queries.size(); ++i) {
      std::vector<double> one(bands, -3.0);
      ASSERT_EQ(status[i], interp->SpectrumAt(queries[i], one)) << i;
      const std::vector<double> row(spectra.begin() + static_cast<std::ptrdiff_t>(i * bands),
                                    spectra.begin() + static_cast<std::ptrdiff_t>((i + 1) * bands));
      if (status[i] == InterpStatus::kOk) {
        EXPECT_EQ(row, one) << i;
      } else {
        ++failed;
        for (double v : row) ASSERT_TRUE(std::isnan(v)) << i;
      }
    }
    if (interp->method() == Method::kOctant) {
      EXPECT_GT(failed, 100u);
    }
  }
}

// SpectraAt on `queries` against SpectrumAt query by query: statuses, and rows bit for bit (NaN
// rows for failures).
void ExpectSpectraAtIsSpectrumAt(const OctantInterpolator& interp,
                                 const std::vector<Point>& queries) {
  std::vector<double> flat;
  for (const Point& q : queries) flat.insert(flat.end(), q.begin(), q.end());
  const auto bands = static_cast<std::size_t>(interp.bands());
  std::vector<InterpStatus> status(queries.size());
  std::vector<double> spectra(queries.size() * bands, -3.0);
  interp.SpectraAt(flat, status, spectra);
  std::size_t ok = 0;
  for (std::size_t i = 0; i < queries.size(); ++i) {
    std::vector<double> one(bands, -3.0);
    ASSERT_EQ(status[i], interp.SpectrumAt(queries[i], one)) << i;
    const std::vector<double> row(spectra.begin() + static_cast<std::ptrdiff_t>(i * bands),
                                  spectra.begin() + static_cast<std::ptrdiff_t>((i + 1) * bands));
    if (status[i] == InterpStatus::kOk) {
      ++ok;
      ASSERT_EQ(row, one) << i;
    } else {
      for (double v : row) ASSERT_TRUE(std::isnan(v)) << i;
    }
  }
  EXPECT_GT(ok, queries.size() / 2);
}

TEST(OctantFastPathTest, LargeBatchSortedByCellIsSpectrumAtQueryByQuery) {
  // Batches large enough for SpectraAt to sort their queries by cell (a quarter of a query per
  // cell or more): random queries in and around the data, runs of one repeated query (more than
  // one group of lanes in a cell), the samples themselves (ties), queries outside the grid,
  // invalid queries. 66,536 queries: a window of 65,536 sorted, then 1,000 too few to sort.
  const auto grid = PaperGrid();
  auto queries = RandomPoints(66536, {-5, -5, -5}, {95, 95, 185}, 32);
  for (std::size_t k = 0; k < 2000; ++k) queries[k] = queries[k / 20 + 30000];
  for (std::size_t k = 0; k < grid.size(); ++k) queries[2000 + k] = grid[k];
  queries[7000] = {1, NAN, 1};
  queries[7001] = {INFINITY, 1, 1};
  queries[7002] = {-1e300, 1e300, 0};
  {
    SCOPED_TRACE("rig grid: cells of the orthant grid, shared list scans");
    const auto samples = MakeSamples(grid, AnalyticSpectrum(3));
    for (const Options& options : {Options{}, Options{{1, 1, 0.5}, true, true}}) {
      const auto interp = OctantInterpolator::Create(samples, options).value();
      ASSERT_EQ(interp->search(), OctantInterpolator::Search::kGridThenTree);
      ExpectSpectraAtIsSpectrumAt(*interp, queries);
    }
  }
  {
    SCOPED_TRACE("20,000 random points: no orthant grid, cells of the seed grid");
    const auto points = RandomPoints(20000, {0, 0, 0}, {90, 90, 360}, 33);
    const auto samples = MakeSamples(points, AnalyticSpectrum(3));
    const auto interp = OctantInterpolator::Create(samples).value();
    ASSERT_EQ(interp->search(), OctantInterpolator::Search::kTree);
    auto around = RandomPoints(20000, {-5, -5, -5}, {95, 95, 365}, 34);
    for (std::size_t k = 0; k < 1000; ++k) around[k] = points[k];
    around[1000] = {NAN, 1, 1};
    ExpectSpectraAtIsSpectrumAt(*interp, around);
  }
}

void ExpectSameAnswer(const Interpolation& got, const Interpolation& want) {
  ASSERT_EQ(got.status, want.status);
  EXPECT_EQ(got.method, want.method);
  EXPECT_EQ(got.spectrum, want.spectrum);
  EXPECT_EQ(got.detail, want.detail);
  ASSERT_EQ(got.vertices.size(), want.vertices.size());
  for (std::size_t k = 0; k < want.vertices.size(); ++k) {
    EXPECT_EQ(got.vertices[k].id, want.vertices[k].id);
    EXPECT_EQ(got.vertices[k].index, want.vertices[k].index);
    EXPECT_EQ(got.vertices[k].coords, want.vertices[k].coords);
    EXPECT_EQ(got.vertices[k].weight, want.vertices[k].weight);
  }
}

TEST(OctantFastPathTest, EvaluateEachSortsLargeBatchesAndIsEvaluateBitForBit) {
  // InterpolateBatch's path: full answers with provenance, a large batch sorted by cell, handed
  // over in query order. 70,000 queries: a window of 65,536 sorted, then 4,464 (sorted if that
  // is a quarter of a query per cell of the grid); samples (ties), invalid queries and
  // queries outside the data (Evaluate's own answers, with their empty orthants named).
  const auto grid = PaperGrid();
  auto queries = RandomPoints(70000, {-5, -5, -5}, {95, 95, 185}, 41);
  for (std::size_t k = 0; k < grid.size(); ++k) queries[k] = grid[k];
  queries[5000] = {1, NAN, 1};
  queries[5001] = {-1e300, 1e300, 0};
  std::vector<double> flat;
  for (const Point& q : queries) flat.insert(flat.end(), q.begin(), q.end());
  const auto samples = MakeSamples(grid, AnalyticSpectrum(3));
  for (const Options& options : {Options{}, Options{{1, 1, 0.5}, true, true}}) {
    const auto interp = OctantInterpolator::Create(samples, options).value();
    std::size_t next = 0;
    interp->EvaluateEach(flat, [&](std::size_t i, Interpolation&& answer) {
      EXPECT_EQ(i, next++);
      ExpectSameAnswer(answer, interp->Evaluate(queries[i]));
      return !::testing::Test::HasFatalFailure();
    });
    EXPECT_EQ(next, queries.size());
    const std::uint64_t sorted = interp->sorted_queries();
    EXPECT_TRUE(sorted == 65536 || sorted == queries.size()) << sorted;

    // A batch too small to sort goes query by query (the counter stays), with the same answers.
    const std::span<const double> few = std::span<const double>(flat).first(3 * 100);
    interp->EvaluateEach(few, [&](std::size_t i, Interpolation&& answer) {
      ExpectSameAnswer(answer, interp->Evaluate(queries[i]));
      return true;
    });
    EXPECT_EQ(interp->sorted_queries(), sorted);
    // `take` returning false stops the batch.
    std::size_t taken = 0;
    interp->EvaluateEach(flat, [&](std::size_t i, Interpolation&&) { return ++taken, i < 9; });
    EXPECT_EQ(taken, 10u);
  }
}

TEST(NearestFastPathTest, SpectrumAtIsTheNearestSamplesSpectrum) {
  const auto points = RandomPoints(2000, {0, 0, 0}, {90, 90, 360}, 14);
  const auto samples = MakeSamples(points, LinearSpectrum(3, 3));
  auto nearest = MakeNearestInterpolator(samples).value();
  for (const Point& q : RandomPoints(1000, {-5, -5, -5}, {95, 95, 365}, 15)) {
    std::vector<double> spectrum(3);
    ASSERT_EQ(nearest->SpectrumAt(q, spectrum), InterpStatus::kOk);
    EXPECT_EQ(spectrum, nearest->Evaluate(q).spectrum);
  }
  std::vector<double> spectrum(3);
  EXPECT_EQ(nearest->SpectrumAt(Point{1, INFINITY, 1}, spectrum), InterpStatus::kOutsideHull);
}

// The brute-force definition: per orthant, the nearest point, ties to the lower rank.
void ScanWinners(const PointCloud& cloud, const double* p, OrthantWinners& w) {
  std::array<double, kMaxOrthants> best{};
  best.fill(std::numeric_limits<double>::infinity());
  w.rank.fill(kNoPoint);
  const int d = cloud.dims;
  for (std::size_t r = 0; r < cloud.size(); ++r) {
    const double* x = cloud.scaled_point(r).data();
    const auto o = static_cast<std::size_t>(OrthantOf(x, p, d));
    const double d2 = SquaredDistance(x, p, d);
    if (d2 < best[o] || (d2 == best[o] && w.rank[o] == kNoPoint)) {
      best[o] = d2;
      w.rank[o] = static_cast<std::uint32_t>(r);
    }
  }
}

// 3 copies of each point of the 3D lattice of side × side × side unit steps (ties everywhere).
std::vector<Point> TriplicatedLattice(int side) {
  std::vector<Point> out;
  for (int copy = 0; copy < 3; ++copy) {
    for (const Point& p : Lattice(3, side)) out.push_back(p);
  }
  return out;
}

// n queries on the half-step lattice from −0.5, `steps` per axis (last axis from 0), in order:
// on lattice points, on the planes between them, and half-way.
std::vector<Point> HalfSteps(int steps, int n) {
  std::vector<Point> out;
  for (int k = 0; k < n; ++k) {
    out.push_back({0.5 * (k % steps) - 0.5, 0.5 * ((k / steps) % steps) - 0.5,
                   0.5 * ((k / (steps * steps)) % steps)});
  }
  return out;
}

TEST(KdTreeKernelTest, EveryKernelFindsTheScansWinners) {
  struct Case {
    const char* name;
    std::vector<Point> points;
    std::vector<Point> queries;
  };
  std::vector<Case> cases;
  cases.push_back({"paper grid", PaperGrid(), RandomPoints(2000, {-5, -5, -5}, {95, 95, 185}, 21)});
  cases.push_back({"random 3D", RandomPoints(5000, {0, 0, 0}, {90, 90, 360}, 22),
                   RandomPoints(2000, {-5, -5, -5}, {95, 95, 365}, 23)});
  cases.push_back({"random 4D", RandomPoints(3000, {0, 0, 0, 0}, {90, 360, 90, 360}, 24),
                   RandomPoints(1000, {0, 0, 0, 0}, {90, 360, 90, 360}, 25)});
  // Ties everywhere and points on the splitting planes; 3 copies of each lattice point.
  cases.push_back({"lattice with duplicates", TriplicatedLattice(7), HalfSteps(15, 2000)});
  std::vector<Point> lattice4 = Lattice(4, 4);
  std::vector<Point> half4;
  for (int k = 0; k < 1000; ++k) {
    half4.push_back(
        {0.5 * (k % 9) - 0.5, 0.5 * ((k / 9) % 9) - 0.5, 0.5 * ((k / 81) % 9), 0.5 * (k % 7)});
  }
  cases.push_back({"4D lattice", lattice4, half4});

  for (const Case& c : cases) {
    SCOPED_TRACE(c.name);
    const auto samples =
        MakeSamples(c.points, LinearSpectrum(static_cast<int>(c.points[0].size()), 1));
    const PointCloud cloud = BuildPointCloud(*samples, {}).value();
    for (KdTree::Kernel kernel :
         {KdTree::Kernel::kScalar, KdTree::Kernel::kAvx2, KdTree::Kernel::kAvx512}) {
      if (!KdTree::Supported(kernel)) continue;
      SCOPED_TRACE(KdTree::KernelName(kernel));
      const KdTree tree(cloud, kernel);
      EXPECT_EQ(tree.kernel(), kernel);
      for (const Point& q : c.queries) {
        OrthantWinners got, want;
        tree.NearestPerOrthant(q.data(), got);
        ScanWinners(cloud, q.data(), want);
        for (std::size_t o = 0; o < (std::size_t{1} << cloud.dims); ++o) {
          ASSERT_EQ(got.rank[o], want.rank[o]) << "orthant " << o;
          if (want.rank[o] != kNoPoint) {
            const auto d = static_cast<std::size_t>(cloud.dims);
            const auto p = cloud.scaled_point(want.rank[o]);
            EXPECT_EQ(std::vector<double>(got.scaled[o], got.scaled[o] + d),
                      std::vector<double>(p.begin(), p.end()));
          }
        }
      }
    }
  }
}

// NearestPerOrthantInCell (several queries of one grid cell at once) against the scan, for
// every kernel, groups of every size from 1 to kCellLanes.
TEST(KdTreeKernelTest, QueriesOfACellTogetherFindTheScansWinners) {
  struct Case {
    const char* name;
    std::vector<Point> points;
    std::vector<Point> queries;
  };
  std::vector<Case> cases;
  cases.push_back(
      {"paper grid", PaperGrid(), RandomPoints(20000, {-5, -5, -5}, {95, 95, 185}, 41)});
  // Ties everywhere: 3 copies of each lattice point, queries on the lattice and half-way.
  cases.push_back({"lattice with duplicates", TriplicatedLattice(9), HalfSteps(17, 20000)});
  std::size_t grouped = 0;
  for (const Case& c : cases) {
    SCOPED_TRACE(c.name);
    const auto samples = MakeSamples(c.points, LinearSpectrum(3, 1));
    const PointCloud cloud = BuildPointCloud(*samples, {}).value();
    for (KdTree::Kernel kernel :
         {KdTree::Kernel::kScalar, KdTree::Kernel::kAvx2, KdTree::Kernel::kAvx512}) {
      if (!KdTree::Supported(kernel)) continue;
      SCOPED_TRACE(KdTree::KernelName(kernel));
      const KdTree tree(cloud, kernel, KdTree::Search::kGridThenTree);
      ASSERT_FALSE(tree.grid().empty());
      std::map<std::uint32_t, std::vector<const double*>> by_cell;
      for (const Point& q : c.queries) {
        const std::uint32_t cell = tree.ListedCell(q.data());
        if (cell != OrthantGrid::kNoCell) by_cell[cell].push_back(q.data());
      }
      std::size_t group_size = 1;  // cycles through 1 … kCellLanes
      for (const auto& [cell, queries] : by_cell) {
        for (std::size_t first = 0; first < queries.size(); first += group_size) {
          const std::size_t count = std::min(group_size, queries.size() - first);
          group_size = group_size % KdTree::kCellLanes + 1;
          std::array<WinnerCube3, KdTree::kCellLanes> cubes;
          tree.NearestPerOrthantInCell(cell, queries.data() + first, static_cast<int>(count),
                                       cubes.data());
          grouped += count > 1 ? count : 0;
          for (std::size_t k = 0; k < count; ++k) {
            const double* q = queries[first + k];
            OrthantWinners want;
            ScanWinners(cloud, q, want);
            for (std::size_t o = 0; o < 8; ++o) {
              SCOPED_TRACE(::testing::Message() << "query " << q[0] << ", " << q[1] << ", " << q[2]
                                                << " in a group of " << count << ", orthant " << o);
              ASSERT_EQ(((cubes[k].empty >> o) & 1u) != 0, want.rank[o] == kNoPoint);
              if (want.rank[o] == kNoPoint) continue;
              ASSERT_EQ(cubes[k].rank[o], want.rank[o]);
              const auto p = cloud.scaled_point(want.rank[o]);
              for (std::size_t j = 0; j < 3; ++j) ASSERT_EQ(cubes[k].axis[j][o], p[j]);
            }
          }
        }
      }
    }
  }
  EXPECT_GT(grouped, 10000u);  // most queries were answered in groups
}

TEST(KdTreeKernelTest, BestKernelIsSupportedAndNamed) {
  const auto samples =
      MakeSamples(RandomPoints(100, {0, 0, 0}, {1, 1, 1}, 3), LinearSpectrum(3, 1));
  const PointCloud cloud = BuildPointCloud(*samples, {}).value();
  const KdTree tree(cloud);
  EXPECT_NE(tree.kernel(), KdTree::Kernel::kBest);
  EXPECT_TRUE(KdTree::Supported(tree.kernel()));
  EXPECT_STRNE(KdTree::KernelName(tree.kernel()), "best");
  EXPECT_TRUE(KdTree::Supported(KdTree::Kernel::kScalar));
}

// Winners of a synthetic cube around q: orthant o's point lies on o's side of q on every axis
// at `scale` · U(0, 1] from it (0 on an axis where `on_plane` picks it: a point on the plane
// belongs to the + side).
OrthantWinners CubeWinners(const Point& q, double scale, std::mt19937_64& rng, bool on_plane) {
  std::uniform_real_distribution<double> u(0.0, 1.0);
  OrthantWinners w{};
  for (std::size_t o = 0; o < 8; ++o) {
    w.rank[o] = static_cast<std::uint32_t>(100 + o);
    for (std::size_t j = 0; j < 3; ++j) {
      const bool plus = ((o >> j) & 1u) != 0;
      double offset = scale * (1.0 - u(rng));  // (0, scale]
      if (on_plane && plus && u(rng) < 0.3) offset = 0.0;
      w.coords[o][j] = plus ? q[j] + offset : q[j] - offset;
    }
    w.scaled[o] = w.coords[o].data();
  }
  return w;
}

void ExpectSameBlendAs(const OctantBlend& got, const OctantBlend& want) {
  ASSERT_EQ(got.status, want.status);
  EXPECT_EQ(got.empty_orthants, want.empty_orthants);
  EXPECT_EQ(got.simplex, want.simplex);
  EXPECT_EQ(got.degenerate, want.degenerate);
  EXPECT_EQ(got.rank, want.rank);
  for (std::size_t k = 0; k < want.weight.size(); ++k) {
    EXPECT_EQ(std::bit_cast<std::uint64_t>(got.weight[k]),
              std::bit_cast<std::uint64_t>(want.weight[k]))
        << "weight " << k << ": " << got.weight[k] << " vs " << want.weight[k];
  }
}

// The same winners as a WinnerCube3 (the batch path's layout).
WinnerCube3 CubeOf(const OrthantWinners& w) {
  WinnerCube3 cube{};
  for (std::size_t o = 0; o < 8; ++o) {
    if (w.rank[o] == kNoPoint) {
      cube.empty |= 1u << o;
      continue;
    }
    cube.rank[o] = w.rank[o];
    for (std::size_t j = 0; j < 3; ++j) cube.axis[j][o] = w.scaled[o][j];
  }
  return cube;
}

void ExpectSameBlendWith(const OrthantWinners& w, const Point& q, BlendKernel kernel) {
  const OctantBlend want = FindOctantBlend(w, q, 3);
  {
    SCOPED_TRACE("OrthantWinners");
    ExpectSameBlendAs(FindOctantBlendFast(w, q, 3, kernel), want);
  }
  SCOPED_TRACE("WinnerCube3");
  ExpectSameBlendAs(FindOctantBlendFast(CubeOf(w), q.data(), kernel), want);
}

// Every blend kernel this CPU runs (AVX-512 and AVX2 both, where it has AVX-512).
void ExpectSameBlend(const OrthantWinners& w, const Point& q) {
  for (BlendKernel kernel :
       {BlendKernel::kBest, BlendKernel::kScalar, BlendKernel::kAvx2, BlendKernel::kAvx512}) {
    if (!BlendKernelSupported(kernel)) continue;
    SCOPED_TRACE(::testing::Message() << "blend kernel " << static_cast<int>(kernel));
    ExpectSameBlendWith(w, q, kernel);
  }
}

TEST(OctantBlendFastTest, SameBlendAsFindOctantBlendBitForBit) {
  std::mt19937_64 rng(20261122);
  std::uniform_real_distribution<double> u(0.0, 1.0);
  // Scales from tiny (outside the degenerate test's quick range) to large; cubes with points on
  // the query's planes; cubes whose corners coincide or are flat; queries on vertices.
  const double scales[] = {1e-110, 1e-30, 1e-3, 1.0, 7.5, 1e3, 1e60};
  int ok = 0, flat = 0;
  for (double scale : scales) {
    for (int i = 0; i < 400; ++i) {
      SCOPED_TRACE(::testing::Message() << "scale " << scale << " case " << i);
      const Point q = {90 * u(rng), 90 * u(rng), 360 * u(rng)};
      OrthantWinners w = CubeWinners(q, scale, rng, /*on_plane=*/i % 2 == 1);
      switch (i % 8) {
        case 2:  // two corners at the same place (every tetrahedron with both is flat)
          w.coords[5] = w.coords[3];
          break;
        case 4:  // all corners on one plane φ = q_φ: every tetrahedron flat
          for (auto& c : w.coords) c[2] = q[2];
          break;
        case 6:  // the query is the cube's corner A (exactly one-hot weights where A is used)
          w.coords[0] = {q[0], q[1], q[2], 0.0};
          break;
        default:
          break;
      }
      ExpectSameBlend(w, q);
      const OctantBlend b = FindOctantBlend(w, q, 3);
      ok += b.status == InterpStatus::kOk;
      flat += b.degenerate > 0;
    }
  }
  // The cases cover both outcomes and flat tetrahedra.
  EXPECT_GT(ok, 0);
  EXPECT_GT(flat, 0);
  // An empty orthant.
  const Point q = {10, 20, 30};
  OrthantWinners w = CubeWinners(q, 1.0, rng, false);
  w.rank[6] = kNoPoint;
  w.scaled[6] = nullptr;
  ExpectSameBlend(w, q);
}

}  // namespace
}  // namespace brdf::interp
