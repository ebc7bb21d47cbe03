// Properties of the paper's octant method (core/interp/octant/octant.h), checked on the paper's rig
// grid, random sets, lattices and hand-built configurations. No snapshots: every expectation
// follows from the method's definition in docs/interpolation.md.
#include "core/interp/octant/octant.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <numeric>
#include <random>

#include "core/interp/interpolator.h"
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

std::unique_ptr<Interpolator> Octant(std::shared_ptr<const SampleSet> samples,
                                     const Options& options = {}) {
  auto r = MakeOctantInterpolator(std::move(samples), options);
  EXPECT_TRUE(r.ok()) << r.status().ToString();
  return std::move(r).value();
}

// Checks everything a successful blend promises: dims + 1 vertices that are samples, weights
// >= 0 summing to 1, weights that reproduce the query's position, and every band of the spectrum
// between the smallest and largest vertex value.
void ExpectValidBlend(const Interpolation& r, const SampleSet& samples, const Point& query) {
  ASSERT_EQ(r.status, InterpStatus::kOk) << r.detail;
  const auto dims = static_cast<std::size_t>(samples.dims());
  ASSERT_EQ(r.vertices.size(), dims + 1);
  ASSERT_EQ(r.spectrum.size(), static_cast<std::size_t>(samples.bands()));
  double sum = 0;
  Point position(dims, 0.0);
  for (const Vertex& v : r.vertices) {
    ASSERT_LT(v.index, samples.size());
    EXPECT_EQ(v.id, samples.id(v.index));
    EXPECT_GE(v.weight, 0.0);
    sum += v.weight;
    for (std::size_t j = 0; j < dims; ++j) position[j] += v.weight * v.coords[j];
  }
  EXPECT_NEAR(sum, 1.0, 1e-12);
  for (std::size_t j = 0; j < dims; ++j) EXPECT_NEAR(position[j], query[j], 1e-9) << "axis " << j;
  for (std::size_t b = 0; b < r.spectrum.size(); ++b) {
    double lo = INFINITY, hi = -INFINITY;
    for (const Vertex& v : r.vertices) {
      lo = std::min(lo, samples.spectrum(v.index)[b]);
      hi = std::max(hi, samples.spectrum(v.index)[b]);
    }
    const double tol = 1e-13 * std::max(1.0, std::fabs(hi));
    EXPECT_GE(r.spectrum[b], lo - tol) << "band " << b;
    EXPECT_LE(r.spectrum[b], hi + tol) << "band " << b;
  }
}

TEST(OctantTest, BlendsOnThePapersGridAreConvexAndReproduceTheQuery) {
  int poses = 0;
  const auto grid = PaperGrid(&poses);
  ASSERT_EQ(poses, 2320);  // geometry.md's counts for the sample-rotation loops
  ASSERT_EQ(grid.size(), 2153u);
  const auto samples = MakeSamples(grid, AnalyticSpectrum(3));
  const auto octant = Octant(samples);
  const auto queries = RandomPoints(3000, {0, 0, 0}, {80, 80, 180}, 11);
  int ok = 0;
  for (const Point& q : queries) {
    const Interpolation r = octant->Evaluate(q);
    EXPECT_EQ(r.method, Method::kOctant);
    if (r.status != InterpStatus::kOk) {
      EXPECT_EQ(r.status, InterpStatus::kEmptyOctant) << r.detail;
      EXPECT_TRUE(r.spectrum.empty());
      continue;
    }
    ++ok;
    ExpectValidBlend(r, *samples, q);
    // The vertices of a tetrahedron are the winners of four different octants.
    for (std::size_t a = 0; a < r.vertices.size(); ++a) {
      for (std::size_t b = a + 1; b < r.vertices.size(); ++b) {
        EXPECT_NE(r.vertices[a].coords, r.vertices[b].coords);
      }
    }
  }
  EXPECT_GT(ok, 2000);  // most of the rig's range is covered
}

TEST(OctantTest, ReproducesLinearSpectraExactly) {
  for (int dims : {3, 4}) {
    SCOPED_TRACE(dims);
    const std::vector<double> lo(static_cast<std::size_t>(dims), 0.0);
    const std::vector<double> hi =
        dims == 3 ? std::vector<double>{90, 90, 180} : std::vector<double>{90, 360, 90, 360};
    const auto points = RandomPoints(dims == 3 ? 3000 : 6000, lo, hi, 21);
    const auto fn = LinearSpectrum(dims, 7);
    const auto samples = MakeSamples(points, fn);
    const auto octant = Octant(samples);
    std::vector<double> qlo(lo.size()), qhi(hi.size());
    for (std::size_t j = 0; j < lo.size(); ++j) {
      qlo[j] = hi[j] * 0.1;
      qhi[j] = hi[j] * 0.9;
    }
    int ok = 0;
    for (const Point& q : RandomPoints(1000, qlo, qhi, 22)) {
      const Interpolation r = octant->Evaluate(q);
      if (r.status != InterpStatus::kOk) continue;
      ++ok;
      ExpectValidBlend(r, *samples, q);
      const auto truth = fn(q);
      for (std::size_t b = 0; b < truth.size(); ++b) EXPECT_NEAR(r.spectrum[b], truth[b], 1e-9);
    }
    EXPECT_GT(ok, 900);
  }
}

TEST(OctantTest, IsExactAtInteriorLatticePoints) {
  // At a lattice point the winners are the corners of the unit cube below it, the query is corner
  // G, and CFGH (the first tetrahedron containing G) gives it weight exactly 1.
  const auto points = Lattice(3, 6, 2.5);
  const auto samples = MakeSamples(points, AnalyticSpectrum(3));
  const auto octant = Octant(samples);
  int checked = 0;
  for (std::size_t i = 0; i < points.size(); ++i) {
    const Point& q = points[i];
    if (std::any_of(q.begin(), q.end(), [](double x) { return x == 0; })) continue;
    const Interpolation r = octant->Evaluate(q);
    ASSERT_EQ(r.status, InterpStatus::kOk) << r.detail;
    ++checked;
    const auto truth = samples->spectrum(i);
    for (std::size_t b = 0; b < truth.size(); ++b) EXPECT_EQ(r.spectrum[b], truth[b]);
    const auto it = std::find_if(r.vertices.begin(), r.vertices.end(),
                                 [&](const Vertex& v) { return v.index == i; });
    ASSERT_NE(it, r.vertices.end());
    EXPECT_EQ(it->weight, 1.0);
  }
  EXPECT_EQ(checked, 125);
}

TEST(OctantTest, AtASampleThatIsAVertexTheWeightIsOne) {
  // At a sample point that sample wins the (+,+,+) octant. Whenever it is a vertex of the answer,
  // the answer is that sample exactly (another tetrahedron may enclose it first: see
  // core/interp/octant/octant.h).
  const auto points = RandomPoints(2000, {0, 0, 0}, {90, 90, 180}, 31);
  const auto samples = MakeSamples(points, AnalyticSpectrum(3));
  const auto octant = Octant(samples);
  int as_vertex = 0, elsewhere = 0;
  for (std::size_t i = 0; i < points.size(); ++i) {
    const Interpolation r = octant->Evaluate(points[i]);
    if (r.status != InterpStatus::kOk) continue;
    ExpectValidBlend(r, *samples, points[i]);
    const auto it = std::find_if(r.vertices.begin(), r.vertices.end(),
                                 [&](const Vertex& v) { return v.index == i; });
    if (it == r.vertices.end()) {
      ++elsewhere;
      continue;
    }
    ++as_vertex;
    EXPECT_EQ(it->weight, 1.0);
    for (std::size_t b = 0; b < r.spectrum.size(); ++b) {
      EXPECT_EQ(r.spectrum[b], samples->spectrum(i)[b]);
    }
  }
  EXPECT_GT(as_vertex, 1000);
  EXPECT_GT(elsewhere, 0);  // the documented limitation does occur
}

TEST(OctantTest, ShufflingTheSamplesDoesNotChangeTheAnswer) {
  const auto points = RandomPoints(4000, {0, 0, 0}, {90, 90, 180}, 41);
  const auto fn = AnalyticSpectrum(3);
  const auto samples = MakeSamples(points, fn, 1000);
  std::vector<std::size_t> perm(points.size());
  std::iota(perm.begin(), perm.end(), 0);
  std::shuffle(perm.begin(), perm.end(), std::mt19937_64(42));
  auto shuffled = std::make_shared<SampleSet>(3, samples->bands());
  for (std::size_t k : perm) {
    ASSERT_TRUE(shuffled->Add(samples->id(k), samples->coords(k), samples->spectrum(k)).ok());
  }
  const auto a = Octant(samples);
  const auto b = Octant(shuffled);
  int ok = 0;
  for (const Point& q : RandomPoints(2000, {0, 0, 0}, {90, 90, 180}, 43)) {
    const Interpolation ra = a->Evaluate(q);
    const Interpolation rb = b->Evaluate(q);
    ASSERT_EQ(ra.status, rb.status);
    EXPECT_EQ(ra.detail, rb.detail);
    ASSERT_EQ(ra.vertices.size(), rb.vertices.size());
    for (std::size_t k = 0; k < ra.vertices.size(); ++k) {
      EXPECT_EQ(ra.vertices[k].id, rb.vertices[k].id);
      EXPECT_EQ(ra.vertices[k].weight, rb.vertices[k].weight);
      EXPECT_EQ(ra.vertices[k].coords, rb.vertices[k].coords);
      EXPECT_EQ(perm[rb.vertices[k].index], ra.vertices[k].index);
    }
    EXPECT_EQ(ra.spectrum, rb.spectrum);
    ok += ra.status == InterpStatus::kOk;
  }
  EXPECT_GT(ok, 1500);
}

TEST(OctantTest, FourDimensionalAnisotropicData) {
  // Brushed (anisotropic) BRDF sampled at random 4D points; 5 vertices per answer, convex
  // blends, and an error against the truth well below the nearest sample's.
  const std::vector<double> lo = {0, 0, 0, 0}, hi = {80, 360, 80, 360};
  const auto fn = AnalyticSpectrum(4);
  const auto samples = MakeSamples(RandomPoints(20000, lo, hi, 51), fn);
  const auto octant = Octant(samples);
  double err2 = 0, nearest_err2 = 0;
  int ok = 0;
  for (const Point& q : RandomPoints(400, {10, 40, 10, 40}, {70, 320, 70, 320}, 52)) {
    const Interpolation r = octant->Evaluate(q);
    if (r.status != InterpStatus::kOk) {
      EXPECT_EQ(r.status, InterpStatus::kEmptyOctant) << r.detail;
      continue;
    }
    ++ok;
    ExpectValidBlend(r, *samples, q);
    EXPECT_NE(r.detail.find("Kuhn simplex"), std::string::npos) << r.detail;
    const auto truth = fn(q);
    std::size_t nearest = 0;
    double best = INFINITY;
    for (std::size_t i = 0; i < samples->size(); ++i) {
      double d2 = 0;
      for (std::size_t j = 0; j < 4; ++j) d2 += std::pow(samples->coords(i)[j] - q[j], 2);
      if (d2 < best) best = d2, nearest = i;
    }
    for (std::size_t b = 0; b < truth.size(); ++b) {
      err2 += std::pow(r.spectrum[b] - truth[b], 2);
      nearest_err2 += std::pow(samples->spectrum(nearest)[b] - truth[b], 2);
    }
  }
  EXPECT_GT(ok, 380);
  EXPECT_LT(err2, nearest_err2);
}

TEST(OctantTest, EmptyOctantsAreNamed) {
  const auto samples = MakeSamples(Lattice(3, 4, 10.0), LinearSpectrum(3, 3));
  const auto octant = Octant(samples);
  // Below every θi sample: the four θi− octants A, D, E, H are empty.
  const Interpolation r = octant->Evaluate(Point{-1, 15, 15});
  EXPECT_EQ(r.status, InterpStatus::kEmptyOctant);
  EXPECT_TRUE(r.spectrum.empty());
  EXPECT_TRUE(r.vertices.empty());
  for (const char* name : {"octant A (θi−, θo−, φ−)", "octant D", "octant E", "octant H"}) {
    EXPECT_NE(r.detail.find(name), std::string::npos) << r.detail;
  }
  for (const char* name : {"octant B", "octant C", "octant F", "octant G"}) {
    EXPECT_EQ(r.detail.find(name), std::string::npos) << r.detail;
  }
  // Exactly at the largest φ: φ+ holds only the points on the plane (a point on a splitting
  // plane is on the + side), so nothing is missing; just above it, E, F, G, H are empty.
  EXPECT_EQ(octant->Evaluate(Point{15, 15, 30}).status, InterpStatus::kOk);
  const Interpolation above = octant->Evaluate(Point{15, 15, 30.5});
  EXPECT_EQ(above.status, InterpStatus::kEmptyOctant);
  for (const char* name : {"octant E (", "octant F (", "octant G (", "octant H ("}) {
    EXPECT_NE(above.detail.find(name), std::string::npos) << above.detail;
  }
  EXPECT_EQ(above.detail.find("octant A"), std::string::npos);
}

TEST(OctantTest, NoEnclosingTetrahedronIsReported) {
  // One sample per octant around the origin. C, F, H lie on the plane x + y + z = −1e-10 just
  // below the query, G = 1e-11·(1,1,1) just above it: only the sliver CFGH contains the query,
  // and it is flat (relative volume ~3e-14), so it is skipped; the other four miss the query.
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
  const Interpolation r = Octant(samples)->Evaluate(Point{0, 0, 0});
  EXPECT_EQ(r.status, InterpStatus::kNoEnclosingSimplex);
  EXPECT_TRUE(r.spectrum.empty());
  EXPECT_NE(r.detail.find("1 of them flat"), std::string::npos) << r.detail;
  // The same points, with the query moved into the central tetrahedron, blend fine.
  EXPECT_EQ(Octant(samples)->Evaluate(Point{-1e-3, -1e-3, -1e-3}).status, InterpStatus::kOk);
}

TEST(OctantTest, InvalidQueriesAreReportedNotCrashed) {
  const auto samples = MakeSamples(Lattice(3, 3), LinearSpectrum(3, 2));
  const auto octant = Octant(samples);
  const Interpolation nan = octant->Evaluate(Point{1, NAN, 1});
  EXPECT_EQ(nan.status, InterpStatus::kEmptyOctant);
  EXPECT_NE(nan.detail.find("θo"), std::string::npos) << nan.detail;
  const Interpolation short_query = octant->Evaluate(Point{1, 1});
  EXPECT_EQ(short_query.status, InterpStatus::kEmptyOctant);
  EXPECT_NE(short_query.detail.find("2 coordinates"), std::string::npos) << short_query.detail;
}

TEST(OctantTest, MirrorPhiFillsTheRetroSideAndReportsTheOriginalSample) {
  // Samples at φ >= 5 only: a query at φ = 2 has nothing below it in φ, unless mirrored copies
  // (φ → −φ) fill that side.
  auto points = RandomPoints(3000, {0, 0, 5}, {90, 90, 180}, 61);
  const auto fn = AnalyticSpectrum(3);
  const auto samples = MakeSamples(points, fn, 7);
  const Point q = {40, 50, 2};
  EXPECT_EQ(Octant(samples)->Evaluate(q).status, InterpStatus::kEmptyOctant);
  Options mirror;
  mirror.mirror_phi = true;
  const Interpolation r = Octant(samples, mirror)->Evaluate(q);
  ASSERT_EQ(r.status, InterpStatus::kOk) << r.detail;
  int mirrored = 0;
  for (const Vertex& v : r.vertices) {
    const auto c = samples->coords(v.index);
    EXPECT_EQ(v.id, static_cast<std::int64_t>(v.index) + 7);
    EXPECT_EQ(v.coords[0], c[0]);
    EXPECT_EQ(v.coords[1], c[1]);
    if (v.coords[2] < 0) {
      ++mirrored;
      EXPECT_EQ(v.coords[2], -c[2]);
    } else {
      EXPECT_EQ(v.coords[2], c[2]);
    }
  }
  EXPECT_GT(mirrored, 0);
  double position = 0;
  for (const Vertex& v : r.vertices) position += v.weight * v.coords[2];
  EXPECT_NEAR(position, q[2], 1e-9);
}

TEST(OctantTest, ReciprocityUsesSwappedCopies) {
  // Samples only where θi > θo: a query with θi < θo needs the swapped copies (θo, θi, φ).
  std::vector<Point> points;
  for (const Point& p : RandomPoints(6000, {0, 0, 0}, {90, 90, 180}, 71)) {
    if (p[0] > p[1]) points.push_back(p);
  }
  const auto samples = MakeSamples(points, AnalyticSpectrum(3));
  const Point q = {20, 60, 90};
  Options reciprocity;
  reciprocity.reciprocity = true;
  const Interpolation r = Octant(samples, reciprocity)->Evaluate(q);
  ASSERT_EQ(r.status, InterpStatus::kOk) << r.detail;
  for (const Vertex& v : r.vertices) {
    const auto c = samples->coords(v.index);
    // Every vertex near the query is a swapped copy of a measured sample.
    EXPECT_EQ(v.coords[0], c[1]);
    EXPECT_EQ(v.coords[1], c[0]);
    EXPECT_EQ(v.coords[2], c[2]);
  }
}

TEST(OctantTest, UniformPowerOfTwoScaleChangesNothingAndAnisotropicScaleChangesNeighbours) {
  const auto points = RandomPoints(3000, {0, 0, 0}, {90, 90, 180}, 81);
  const auto samples = MakeSamples(points, AnalyticSpectrum(3));
  const auto plain = Octant(samples);
  Options doubled;
  doubled.axis_scale = {2, 2, 2};  // exact in binary: every distance and weight is the same
  Options squeezed;
  squeezed.axis_scale = {1, 1, 0.25};
  const auto scaled = Octant(samples, doubled);
  const auto other = Octant(samples, squeezed);
  int differ = 0;
  for (const Point& q : RandomPoints(500, {10, 10, 10}, {80, 80, 170}, 82)) {
    const Interpolation a = plain->Evaluate(q);
    const Interpolation b = scaled->Evaluate(q);
    ASSERT_EQ(a.status, b.status);
    EXPECT_EQ(a.spectrum, b.spectrum);
    const Interpolation c = other->Evaluate(q);
    if (a.status == InterpStatus::kOk && c.status == InterpStatus::kOk) {
      ExpectValidBlend(c, *samples, q);
      differ +=
          a.vertices[0].index != c.vertices[0].index || a.vertices[1].index != c.vertices[1].index;
    }
  }
  EXPECT_GT(differ, 100);
}

TEST(OctantTest, BadInputsAreRejected) {
  EXPECT_EQ(MakeOctantInterpolator(nullptr).status().code(), StatusCode::kInvalidArgument);
  const auto empty = std::make_shared<SampleSet>(3, 4);
  const auto r = MakeOctantInterpolator(empty);
  EXPECT_EQ(r.status().code(), StatusCode::kInvalidArgument);
  EXPECT_NE(r.status().message().find("empty"), std::string::npos);
}

}  // namespace
}  // namespace brdf::interp
