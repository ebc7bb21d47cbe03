// The indexed octant method (k-d tree) against the paper's O(N) scan: the answers must be
// bit-identical — statuses, details, vertices (ids, indices, coordinates, weights) and spectra —
// on the paper's grid, random sets, integer lattices full of distance ties and points on the
// splitting planes, heavy duplicates, with and without symmetry augmentation and axis scaling.
// The nearest-neighbour method shares the index and is checked against a scan written here.
#include <gtest/gtest.h>

#include <cmath>
#include <limits>

#include "core/interp/nearest.h"
#include "core/interp/octant/octant.h"
#include "core/interp/octant/reference.h"
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

void ExpectIdentical(const Interpolation& fast, const Interpolation& ref, const Point& q) {
  SCOPED_TRACE(::testing::Message() << "query " << q[0] << ", " << q[1] << ", " << q[2]);
  ASSERT_EQ(fast.status, ref.status) << fast.detail << " vs " << ref.detail;
  EXPECT_EQ(fast.method, ref.method);
  EXPECT_EQ(fast.detail, ref.detail);
  ASSERT_EQ(fast.vertices.size(), ref.vertices.size());
  for (std::size_t k = 0; k < fast.vertices.size(); ++k) {
    EXPECT_EQ(fast.vertices[k].id, ref.vertices[k].id);
    EXPECT_EQ(fast.vertices[k].index, ref.vertices[k].index);
    EXPECT_EQ(fast.vertices[k].coords, ref.vertices[k].coords);
    EXPECT_EQ(fast.vertices[k].weight, ref.vertices[k].weight);  // bitwise: no tolerance
  }
  EXPECT_EQ(fast.spectrum, ref.spectrum);
}

struct Counts {
  int ok = 0, empty = 0, no_simplex = 0;
};

Counts CompareOn(std::shared_ptr<const SampleSet> samples, const std::vector<Point>& queries,
                 const Options& options = {}) {
  auto fast = MakeOctantInterpolator(samples, options);
  auto ref = MakeOctantReferenceInterpolator(samples, options);
  EXPECT_TRUE(fast.ok() && ref.ok());
  Counts counts;
  for (const Point& q : queries) {
    const Interpolation a = (*fast)->Evaluate(q);
    const Interpolation b = (*ref)->Evaluate(q);
    ExpectIdentical(a, b, q);
    counts.ok += a.status == InterpStatus::kOk;
    counts.empty += a.status == InterpStatus::kEmptyOctant;
    counts.no_simplex += a.status == InterpStatus::kNoEnclosingSimplex;
  }
  return counts;
}

// Queries that sit on the data's own coordinates: at samples, and sharing one or two
// coordinates with a sample (on its splitting planes).
std::vector<Point> OnPlaneQueries(const std::vector<Point>& points, std::size_t count,
                                  std::uint64_t seed) {
  std::mt19937_64 rng(seed);
  std::vector<Point> out;
  const auto random = RandomPoints(count, std::vector<double>(points[0].size(), 0.0),
                                   std::vector<double>(points[0].size(), 1.0), seed + 1);
  for (std::size_t k = 0; k < count; ++k) {
    Point q = points[rng() % points.size()];
    const Point& other = points[rng() % points.size()];
    const std::size_t mode = k % 3;  // 0: a sample, 1: one coordinate of another, 2: mixed
    for (std::size_t j = 0; j < q.size(); ++j) {
      if (mode == 1 && j == k % q.size()) q[j] = other[j];
      if (mode == 2 && random[k][j] < 0.5) q[j] = other[j];
    }
    out.push_back(q);
  }
  return out;
}

TEST(OctantIndexTest, PapersGrid) {
  const auto grid = PaperGrid();
  const auto samples = MakeSamples(grid, AnalyticSpectrum(3));
  auto queries = RandomPoints(6000, {-5, -5, -5}, {95, 95, 185}, 1);
  const auto on_plane = OnPlaneQueries(grid, 3000, 2);
  queries.insert(queries.end(), on_plane.begin(), on_plane.end());
  const Counts c = CompareOn(samples, queries);
  EXPECT_GT(c.ok, 5000);
  EXPECT_GT(c.empty, 500);

  Options mirror;
  mirror.mirror_phi = true;
  CompareOn(samples, queries, mirror);
  Options both;
  both.mirror_phi = true;
  both.reciprocity = true;
  both.axis_scale = {2, 2, 0.5};
  CompareOn(samples, queries, both);
}

TEST(OctantIndexTest, RandomSets) {
  for (int dims : {3, 4}) {
    SCOPED_TRACE(dims);
    const std::vector<double> lo(static_cast<std::size_t>(dims), 0.0);
    const std::vector<double> hi =
        dims == 3 ? std::vector<double>{90, 90, 360} : std::vector<double>{90, 360, 90, 360};
    for (std::size_t n : {1u, 7u, 100u, 5000u}) {
      const auto points = RandomPoints(n, lo, hi, 10 + n);
      const auto samples = MakeSamples(points, LinearSpectrum(dims, 5));
      std::vector<double> qlo(lo.size()), qhi(hi.size());
      for (std::size_t j = 0; j < lo.size(); ++j) qlo[j] = -10, qhi[j] = hi[j] + 10;
      auto queries = RandomPoints(dims == 3 ? 3000 : 1500, qlo, qhi, 20 + n);
      const auto on_plane = OnPlaneQueries(points, 500, 30 + n);
      queries.insert(queries.end(), on_plane.begin(), on_plane.end());
      const Counts c = CompareOn(samples, queries);
      if (n == 5000) {
        EXPECT_GT(c.ok, 1000);
      }
      Options scaled;
      scaled.axis_scale.assign(static_cast<std::size_t>(dims), 0.3);
      scaled.axis_scale[0] = 1.7;
      CompareOn(samples, queries, scaled);
    }
  }
}

TEST(OctantIndexTest, IntegerLatticesWithTies) {
  // Every distance is a small integer: ties everywhere, points on every splitting plane.
  for (int dims : {3, 4}) {
    SCOPED_TRACE(dims);
    auto points = Lattice(dims, dims == 3 ? 9 : 5);
    std::mt19937_64 rng(5);
    std::shuffle(points.begin(), points.end(), rng);  // so that rank order is not lattice order
    const auto samples = MakeSamples(points, LinearSpectrum(dims, 3));
    std::vector<Point> queries;
    const int hi = dims == 3 ? 9 : 5;
    for (int k = 0; k < 3000; ++k) {
      Point q(static_cast<std::size_t>(dims));
      for (auto& x : q)
        x = 0.5 * static_cast<double>(rng() % static_cast<unsigned>(2 * hi + 2)) - 0.5;
      queries.push_back(q);
    }
    const Counts c = CompareOn(samples, queries);
    // Each coordinate is inside (0, max] for 16 of 20 (3D) or 8 of 12 (4D) values.
    EXPECT_GT(c.ok, dims == 3 ? 1200 : 450);
    if (dims == 3) {
      Options both;
      both.mirror_phi = true;
      both.reciprocity = true;
      CompareOn(samples, queries, both);
    }
  }
}

TEST(OctantIndexTest, HeavyDuplicates) {
  // 40 copies of each of 27 points: the earliest copy must win every time.
  std::vector<Point> points;
  for (int copy = 0; copy < 40; ++copy) {
    for (const Point& p : Lattice(3, 3, 4.0)) points.push_back(p);
  }
  const auto samples = MakeSamples(points, LinearSpectrum(3, 2));
  const auto queries = RandomPoints(2000, {-1, -1, -1}, {9, 9, 9}, 3);
  const Counts c = CompareOn(samples, queries);
  EXPECT_GT(c.ok, 500);
  auto fast = MakeOctantInterpolator(samples);
  for (const Point& q : queries) {
    for (const Vertex& v : (*fast)->Evaluate(q).vertices) EXPECT_LT(v.index, 27u);
  }
}

TEST(OctantIndexTest, EveryStatusAgrees) {
  // The sliver configuration of octant_test.cc: kNoEnclosingSimplex from both implementations.
  const double s = 1e-10, g = 1e-11, big = 1000, half = 500.5;
  const std::vector<Point> points = {{-1.0 / 3, -1.0 / 3, -1.0 / 3},
                                     {big, -half, -half},
                                     {big, big, -2 * big - s},
                                     {-half, big, -half},
                                     {-half, -half, big},
                                     {big, -2 * big - s, big},
                                     {g, g, g},
                                     {-2 * big - s, big, big}};
  const auto samples = MakeSamples(points, LinearSpectrum(3, 2));
  const Counts c = CompareOn(samples, {{0, 0, 0}, {-1e-3, -1e-3, -1e-3}, {5000, 0, 0}});
  EXPECT_EQ(c.no_simplex, 1);
  EXPECT_EQ(c.ok, 1);
  EXPECT_EQ(c.empty, 1);
}

// Nearest neighbour: the index against a scan written here (ties to the earlier point).
TEST(NearestIndexTest, MatchesAScanOnRandomAndLatticeData) {
  for (int dims : {3, 4}) {
    for (bool lattice : {false, true}) {
      SCOPED_TRACE(::testing::Message() << dims << "D, lattice " << lattice);
      std::vector<Point> points =
          lattice ? Lattice(dims, 5)
                  : RandomPoints(3000, std::vector<double>(static_cast<std::size_t>(dims), 0.0),
                                 std::vector<double>(static_cast<std::size_t>(dims), 90.0), 7);
      const auto samples = MakeSamples(points, AnalyticSpectrum(dims));
      auto nearest = MakeNearestInterpolator(samples);
      ASSERT_TRUE(nearest.ok());
      std::mt19937_64 rng(9);
      for (int k = 0; k < 2000; ++k) {
        Point q(static_cast<std::size_t>(dims));
        for (auto& x : q) {
          x = lattice ? 0.5 * static_cast<double>(rng() % 12) - 0.5
                      : -5 + 100 * static_cast<double>(rng() >> 11) * 0x1.0p-53;
        }
        std::size_t best = 0;
        double best_d2 = std::numeric_limits<double>::infinity();
        for (std::size_t i = 0; i < points.size(); ++i) {
          double d2 = 0;
          for (std::size_t j = 0; j < q.size(); ++j)
            d2 += (points[i][j] - q[j]) * (points[i][j] - q[j]);
          if (d2 < best_d2) best_d2 = d2, best = i;
        }
        const Interpolation r = (*nearest)->Evaluate(q);
        ASSERT_EQ(r.status, InterpStatus::kOk);
        EXPECT_EQ(r.method, Method::kNearest);
        ASSERT_EQ(r.vertices.size(), 1u);
        EXPECT_EQ(r.vertices[0].index, best);
        EXPECT_EQ(r.vertices[0].weight, 1.0);
        EXPECT_EQ(r.vertices[0].coords, points[best]);
        const auto s = samples->spectrum(best);
        EXPECT_EQ(r.spectrum, std::vector<double>(s.begin(), s.end()));
      }
    }
  }
}

TEST(NearestIndexTest, MirroredCopiesRankAfterMeasuredSamples) {
  // A sample at φ = 0 and its mirror coincide: the measured one wins. A query at negative φ
  // finds the mirrored copy of the sample at φ = 3, reported as that sample.
  const std::vector<Point> points = {{10, 10, 0}, {10, 10, 3}, {10, 10, 8}};
  const auto samples = MakeSamples(points, LinearSpectrum(3, 2), 100);
  Options mirror;
  mirror.mirror_phi = true;
  auto nearest = MakeNearestInterpolator(samples, mirror);
  ASSERT_TRUE(nearest.ok());
  const Interpolation at_zero = (*nearest)->Evaluate(Point{10, 10, 0});
  EXPECT_EQ(at_zero.vertices.at(0).id, 100);
  const Interpolation r = (*nearest)->Evaluate(Point{10, 10, -2.9});
  ASSERT_EQ(r.vertices.size(), 1u);
  EXPECT_EQ(r.vertices[0].index, 1u);
  EXPECT_EQ(r.vertices[0].id, 101);
  EXPECT_EQ(r.vertices[0].coords, (Point{10, 10, -3}));
  const Interpolation bad = (*nearest)->Evaluate(Point{10, INFINITY, 1});
  EXPECT_EQ(bad.status, InterpStatus::kOutsideHull);
  EXPECT_FALSE(bad.detail.empty());
}

}  // namespace
}  // namespace brdf::interp
