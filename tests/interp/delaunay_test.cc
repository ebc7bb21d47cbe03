// Delaunay interpolation: the triangulation, the point location walk and the blend.
#include "core/interp/delaunay/delaunay.h"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <memory>
#include <random>
#include <set>
#include <thread>
#include <vector>

#include "core/interp/delaunay/cgal.h"
#include "core/interp/delaunay/locate.h"
#include "core/interp/delaunay/qhull.h"
#include "core/interp/interpolator.h"

namespace brdf::interp {
namespace {

using ::testing::HasSubstr;

constexpr int kBands = 4;

// A linear spectrum: band b = offset_b + Σ_j slope_bj · x_j. Barycentric interpolation must
// reproduce it exactly (up to rounding) anywhere inside the hull.
struct LinearField {
  int dims;
  std::vector<double> offset;  // kBands
  std::vector<double> slope;   // kBands × dims

  std::vector<double> At(std::span<const double> x) const {
    std::vector<double> out(offset);
    for (int b = 0; b < kBands; ++b) {
      for (int j = 0; j < dims; ++j) out[b] += slope[b * dims + j] * x[j];
    }
    return out;
  }
};

LinearField MakeField(int dims, std::mt19937_64& rng) {
  std::uniform_real_distribution<double> u(-2.0, 2.0);
  LinearField f{dims, {}, {}};
  for (int b = 0; b < kBands; ++b) f.offset.push_back(10 * u(rng));
  for (int i = 0; i < kBands * dims; ++i) f.slope.push_back(u(rng));
  return f;
}

// The measurement domain: θ in [0, 90), φ in [0, 360).
std::vector<double> Extent(int dims) {
  return dims == 3 ? std::vector<double>{90, 90, 360} : std::vector<double>{90, 360, 90, 360};
}

std::vector<double> RandomPoint(int dims, std::mt19937_64& rng) {
  std::uniform_real_distribution<double> u(0.0, 1.0);
  std::vector<double> x;
  for (double e : Extent(dims)) x.push_back(e * u(rng));
  return x;
}

// `n` random points plus every corner of the domain box, so that the hull is the whole box.
std::vector<std::vector<double>> BoxCloud(int dims, std::size_t n, std::mt19937_64& rng) {
  std::vector<std::vector<double>> pts;
  const auto extent = Extent(dims);
  for (int corner = 0; corner < (1 << dims); ++corner) {
    std::vector<double> x;
    for (int j = 0; j < dims; ++j) x.push_back((corner >> j) & 1 ? extent[j] : 0.0);
    pts.push_back(x);
  }
  for (std::size_t i = 0; i < n; ++i) pts.push_back(RandomPoint(dims, rng));
  return pts;
}

std::shared_ptr<SampleSet> SamplesOf(const std::vector<std::vector<double>>& pts,
                                     const LinearField& f) {
  auto set = std::make_shared<SampleSet>(f.dims, kBands);
  for (std::size_t i = 0; i < pts.size(); ++i) {
    EXPECT_TRUE(set->Add(static_cast<std::int64_t>(1000 + i), pts[i], f.At(pts[i])).ok());
  }
  return set;
}

std::unique_ptr<DelaunayInterpolator> Make(std::shared_ptr<const SampleSet> set,
                                           const Options& options = {}) {
  auto made = DelaunayInterpolator::Create(std::move(set), options);
  EXPECT_TRUE(made.ok()) << made.status().ToString();
  return made.ok() ? std::move(made).value() : nullptr;
}

void ExpectNear(const std::vector<double>& got, const std::vector<double>& want, double tol) {
  ASSERT_EQ(got.size(), want.size());
  for (std::size_t b = 0; b < got.size(); ++b) {
    EXPECT_NEAR(got[b], want[b], tol * (1 + std::abs(want[b]))) << "band " << b;
  }
}

void ExpectValidBlend(const Interpolation& r, const SampleSet& set) {
  ASSERT_EQ(r.status, InterpStatus::kOk) << r.detail;
  ASSERT_EQ(r.vertices.size(), static_cast<std::size_t>(set.dims()) + 1);
  double sum = 0;
  for (const Vertex& v : r.vertices) {
    EXPECT_GE(v.weight, 0.0);
    sum += v.weight;
    ASSERT_LT(v.index, set.size());
    EXPECT_EQ(v.id, set.id(v.index));
  }
  EXPECT_NEAR(sum, 1.0, 1e-12);
  ASSERT_EQ(r.spectrum.size(), static_cast<std::size_t>(set.bands()));
  for (int b = 0; b < set.bands(); ++b) {
    double lo = INFINITY;
    double hi = -INFINITY;
    for (const Vertex& v : r.vertices) {
      lo = std::min(lo, set.spectrum(v.index)[b]);
      hi = std::max(hi, set.spectrum(v.index)[b]);
    }
    const double slack = 1e-12 * (1 + std::abs(lo) + std::abs(hi));
    EXPECT_GE(r.spectrum[b], lo - slack) << "band " << b;
    EXPECT_LE(r.spectrum[b], hi + slack) << "band " << b;
  }
}

class DelaunayDims : public ::testing::TestWithParam<int> {};

TEST_P(DelaunayDims, ReproducesALinearFieldEverywhereInsideTheHull) {
  const int dims = GetParam();
  std::mt19937_64 rng(42 + dims);
  const LinearField f = MakeField(dims, rng);
  auto set = SamplesOf(BoxCloud(dims, dims == 3 ? 3000 : 1500, rng), f);
  auto interp = Make(set);
  ASSERT_NE(interp, nullptr);
  EXPECT_EQ(interp->method(), Method::kDelaunay);
  EXPECT_EQ(interp->dims(), dims);
  for (int q = 0; q < 3000; ++q) {
    const auto x = RandomPoint(dims, rng);
    const Interpolation r = interp->Evaluate(x);
    ASSERT_EQ(r.status, InterpStatus::kOk) << r.detail;  // the box corners make the hull the box
    EXPECT_EQ(r.method, Method::kDelaunay);
    ExpectNear(r.spectrum, f.At(x), 1e-9);
  }
}

TEST_P(DelaunayDims, WeightsAreConvexAndBandsStayBetweenVertexValues) {
  const int dims = GetParam();
  std::mt19937_64 rng(7 + dims);
  std::uniform_real_distribution<double> u(0.0, 1.0);
  auto set = std::make_shared<SampleSet>(dims, kBands);
  const auto pts = BoxCloud(dims, 800, rng);
  for (std::size_t i = 0; i < pts.size(); ++i) {
    std::vector<double> spectrum;  // unrelated to position: the blend must still stay in range
    for (int b = 0; b < kBands; ++b) spectrum.push_back(u(rng) * (b + 1));
    ASSERT_TRUE(set->Add(static_cast<std::int64_t>(i), pts[i], spectrum).ok());
  }
  auto interp = Make(set);
  ASSERT_NE(interp, nullptr);
  for (int q = 0; q < 2000; ++q) {
    const auto x = RandomPoint(dims, rng);
    const Interpolation r = interp->Evaluate(x);
    ExpectValidBlend(r, *set);
    // The weights locate the query: Σ w·vertex = query.
    for (int j = 0; j < dims; ++j) {
      double at = 0;
      for (const Vertex& v : r.vertices) at += v.weight * v.coords[j];
      EXPECT_NEAR(at, x[j], 1e-9 * (1 + std::abs(x[j])));
    }
  }
}

TEST_P(DelaunayDims, IsExactAtEverySample) {
  const int dims = GetParam();
  std::mt19937_64 rng(11 + dims);
  const LinearField f = MakeField(dims, rng);
  const auto pts = BoxCloud(dims, 400, rng);
  auto set = SamplesOf(pts, f);
  // Give every sample a spectrum off the linear field, so only the sample itself can match.
  auto bumpy = std::make_shared<SampleSet>(dims, kBands);
  for (std::size_t i = 0; i < pts.size(); ++i) {
    auto s = f.At(pts[i]);
    for (double& v : s) v += static_cast<double>(i % 7);
    ASSERT_TRUE(bumpy->Add(static_cast<std::int64_t>(i), pts[i], s).ok());
  }
  auto interp = Make(bumpy);
  ASSERT_NE(interp, nullptr);
  for (std::size_t i = 0; i < pts.size(); ++i) {
    const Interpolation r = interp->Evaluate(pts[i]);
    ASSERT_EQ(r.status, InterpStatus::kOk) << r.detail;
    const auto want = bumpy->spectrum(i);
    ExpectNear(r.spectrum, std::vector<double>(want.begin(), want.end()), 1e-9);
    const auto top =
        std::max_element(r.vertices.begin(), r.vertices.end(),
                         [](const Vertex& a, const Vertex& b) { return a.weight < b.weight; });
    EXPECT_EQ(top->index, i);
    EXPECT_NEAR(top->weight, 1.0, 1e-9);
  }
}

TEST_P(DelaunayDims, ReportsQueriesOutsideTheHull) {
  const int dims = GetParam();
  std::mt19937_64 rng(3 + dims);
  const LinearField f = MakeField(dims, rng);
  // Points in the corner simplex Σ x_j / extent_j <= 1 (its vertices included): the box corner
  // opposite the origin is inside the bounding box but far outside the hull.
  const auto extent = Extent(dims);
  std::vector<std::vector<double>> pts;
  pts.push_back(std::vector<double>(dims, 0.0));
  for (int j = 0; j < dims; ++j) {
    std::vector<double> x(dims, 0.0);
    x[j] = extent[j];
    pts.push_back(x);
  }
  while (pts.size() < 600) {
    auto x = RandomPoint(dims, rng);
    double t = 0;
    for (int j = 0; j < dims; ++j) t += x[j] / extent[j];
    if (t <= 1) pts.push_back(x);
  }
  auto set = SamplesOf(pts, f);
  auto interp = Make(set);
  ASSERT_NE(interp, nullptr);

  int inside = 0;
  int outside = 0;
  for (int q = 0; q < 3000; ++q) {
    const auto x = RandomPoint(dims, rng);
    double t = 0;
    for (int j = 0; j < dims; ++j) t += x[j] / extent[j];
    const Interpolation r = interp->Evaluate(x);
    if (t < 1 - 1e-9) {
      ++inside;
      ASSERT_EQ(r.status, InterpStatus::kOk) << r.detail;
      ExpectNear(r.spectrum, f.At(x), 1e-9);
    } else if (t > 1 + 1e-9) {
      ++outside;
      EXPECT_EQ(r.status, InterpStatus::kOutsideHull);
      EXPECT_TRUE(r.spectrum.empty());
      EXPECT_TRUE(r.vertices.empty());
      EXPECT_THAT(r.detail, HasSubstr("outside the convex hull"));
    }
  }
  EXPECT_GT(inside, 10);
  EXPECT_GT(outside, 1000);

  // Just beyond and just inside the slanted hull face Σ x_j / extent_j = 1, by a millionth.
  std::uniform_real_distribution<double> u(0.0, 1.0);
  for (int q = 0; q < 500; ++q) {
    std::vector<double> w(dims);
    double total = 0;
    for (double& v : w) total += (v = u(rng));
    std::vector<double> beyond(dims);
    std::vector<double> within(dims);
    for (int j = 0; j < dims; ++j) {
      beyond[j] = extent[j] * w[j] / total * (1 + 1e-6);
      within[j] = extent[j] * w[j] / total * (1 - 1e-6);
    }
    EXPECT_EQ(interp->Evaluate(beyond).status, InterpStatus::kOutsideHull) << "query " << q;
    const Interpolation r = interp->Evaluate(within);
    ASSERT_EQ(r.status, InterpStatus::kOk) << "query " << q << ": " << r.detail;
    ExpectNear(r.spectrum, f.At(within), 1e-9);
  }

  // Outside the bounding box, and not a number at all.
  std::vector<double> below(dims, 0.0);
  below[0] = -1e-6;
  EXPECT_EQ(interp->Evaluate(below).status, InterpStatus::kOutsideHull);
  std::vector<double> nan(dims, 1.0);
  nan[dims - 1] = std::nan("");
  EXPECT_EQ(interp->Evaluate(nan).status, InterpStatus::kOutsideHull);
  // On the hull (a vertex, the midpoint of a hull edge): inside.
  EXPECT_EQ(interp->Evaluate(std::vector<double>(dims, 0.0)).status, InterpStatus::kOk);
  std::vector<double> edge(dims, 0.0);
  edge[0] = extent[0] / 2;
  edge[dims - 1] = extent[dims - 1] / 2;
  const Interpolation on_edge = interp->Evaluate(edge);
  ASSERT_EQ(on_edge.status, InterpStatus::kOk) << on_edge.detail;
  ExpectNear(on_edge.spectrum, f.At(edge), 1e-9);
}

// In general position the Delaunay triangulation is unique: CGAL's (3-D sessions) and Qhull's
// (4-D, and what the project used before) must give the same simplices, each with its neighbours.
TEST(Delaunay, CgalAndQhullAgreeInGeneralPosition) {
  std::mt19937_64 rng(53);
  std::vector<double> points;
  for (int i = 0; i < 2000; ++i) {
    const auto x = RandomPoint(3, rng);
    points.insert(points.end(), x.begin(), x.end());
  }
  auto simplices = [](const QhullTriangulation& t) {
    std::set<std::array<std::int32_t, 4>> out;
    for (std::size_t s = 0; s + 4 <= t.vertices.size(); s += 4) {
      std::array<std::int32_t, 4> v{t.vertices[s], t.vertices[s + 1], t.vertices[s + 2],
                                    t.vertices[s + 3]};
      std::sort(v.begin(), v.end());
      out.insert(v);
    }
    return out;
  };
  auto cgal = TriangulateWithCgal3(points);
  auto qhull = TriangulateWithQhull(points, 3);
  ASSERT_TRUE(cgal.ok()) << cgal.status().ToString();
  ASSERT_TRUE(qhull.ok()) << qhull.status().ToString();
  EXPECT_GT(cgal->vertices.size(), 4 * 2000u);
  EXPECT_EQ(simplices(*cgal), simplices(*qhull));
  // Neighbours: across the face opposite vertex m lies a simplex holding the other three.
  const std::size_t cells = cgal->vertices.size() / 4;
  for (std::size_t s = 0; s < cells; ++s) {
    for (int m = 0; m < 4; ++m) {
      const std::int32_t n = cgal->neighbours[4 * s + static_cast<std::size_t>(m)];
      if (n < 0) continue;
      ASSERT_LT(static_cast<std::size_t>(n), cells);
      for (int k = 0; k < 4; ++k) {
        if (k == m) continue;
        const std::int32_t v = cgal->vertices[4 * s + static_cast<std::size_t>(k)];
        const auto* first = &cgal->vertices[4 * static_cast<std::size_t>(n)];
        EXPECT_NE(std::find(first, first + 4, v), first + 4) << "simplex " << s << " face " << m;
      }
    }
  }
}

TEST_P(DelaunayDims, WalkAgreesWithScanningEverySimplex) {
  const int dims = GetParam();
  std::mt19937_64 rng(19 + dims);
  std::vector<double> points;
  for (int i = 0; i < 500; ++i) {
    const auto x = RandomPoint(dims, rng);
    points.insert(points.end(), x.begin(), x.end());
  }
  auto triangulation = TriangulateWithQhull(points, dims);
  ASSERT_TRUE(triangulation.ok()) << triangulation.status().ToString();
  auto locator = SimplexLocator::Build(points, dims, std::move(triangulation).value());
  ASSERT_TRUE(locator.ok()) << locator.status().ToString();
  int inside = 0;
  int outside = 0;
  for (int q = 0; q < 2000; ++q) {
    const auto x = RandomPoint(dims, rng);
    const SimplexLocation walked = locator->Locate(x);
    const SimplexLocation scanned = locator->LocateByScan(x);
    ASSERT_EQ(walked.inside, scanned.inside) << "query " << q;
    if (!walked.inside) {
      ++outside;
      continue;
    }
    ++inside;
    // The same point of the same triangulation: same position from either simplex's weights.
    for (int j = 0; j < dims; ++j) {
      double a = 0;
      double b = 0;
      for (int m = 0; m <= dims; ++m) {
        a += walked.weights[m] * points[locator->vertices(walked.simplex)[m] * dims + j];
        b += scanned.weights[m] * points[locator->vertices(scanned.simplex)[m] * dims + j];
      }
      EXPECT_NEAR(a, x[j], 1e-9 * (1 + std::abs(x[j])));
      EXPECT_NEAR(b, x[j], 1e-9 * (1 + std::abs(x[j])));
    }
    // Starting anywhere (a bad hint) reaches an enclosing simplex too.
    const SimplexLocation from_far = locator->LocateFrom(x, static_cast<std::int32_t>(q % 97));
    EXPECT_TRUE(from_far.inside);
  }
  EXPECT_GT(inside, 500);
  EXPECT_GT(outside, 20);  // random points: the hull misses the box's corners
}

INSTANTIATE_TEST_SUITE_P(ThreeAndFourD, DelaunayDims, ::testing::Values(3, 4),
                         [](const auto& param_info) {
                           return std::to_string(param_info.param) + "D";
                         });

TEST(Delaunay, RegularGridIsTriangulatedDespiteCosphericalPoints) {
  // The rig measures on a grid: many points on common spheres, Qhull's hard case (option Qz).
  std::mt19937_64 rng(5);
  const LinearField f = MakeField(3, rng);
  std::vector<std::vector<double>> pts;
  for (int a = 0; a <= 80; a += 10) {
    for (int b = 0; b <= 80; b += 10) {
      for (int p = 0; p <= 180; p += 15) pts.push_back({double(a), double(b), double(p)});
    }
  }
  auto set = SamplesOf(pts, f);
  auto interp = Make(set);
  ASSERT_NE(interp, nullptr);
  EXPECT_EQ(interp->point_count(), pts.size());
  std::uniform_real_distribution<double> u(0.0, 1.0);
  for (int q = 0; q < 3000; ++q) {
    // Random queries, and queries on the grid's planes, where flat simplices would bite.
    std::vector<double> x = {80 * u(rng), 80 * u(rng), 180 * u(rng)};
    if (q % 2 == 0) x[q % 3] = 10.0 * std::floor(x[q % 3] / 10.0);
    const Interpolation r = interp->Evaluate(x);
    ASSERT_EQ(r.status, InterpStatus::kOk) << r.detail;
    ExpectNear(r.spectrum, f.At(x), 1e-9);
    ExpectValidBlend(r, *set);
  }
}

TEST(Delaunay, CoincidentSamplesKeepTheEarlierOne) {
  std::mt19937_64 rng(13);
  const LinearField f = MakeField(3, rng);
  auto pts = BoxCloud(3, 200, rng);
  auto set = SamplesOf(pts, f);
  const std::vector<double> twin = pts[50];
  const std::vector<double> other(kBands, -77.0);
  ASSERT_TRUE(set->Add(9999, twin, other).ok());  // same place, later, different spectrum
  auto interp = Make(set);
  ASSERT_NE(interp, nullptr);
  EXPECT_EQ(interp->point_count(), pts.size());
  const Interpolation r = interp->Evaluate(twin);
  ASSERT_EQ(r.status, InterpStatus::kOk);
  ExpectNear(r.spectrum, f.At(twin), 1e-9);
  for (const Vertex& v : r.vertices) EXPECT_NE(v.id, 9999);
}

TEST(Delaunay, MirrorPhiExtendsTheHullToNegativeAzimuths) {
  std::mt19937_64 rng(17);
  // Spectrum depends on |φ| only, as for an isotropic sample.
  auto set = std::make_shared<SampleSet>(3, kBands);
  const auto pts = BoxCloud(3, 300, rng);
  for (std::size_t i = 0; i < pts.size(); ++i) {
    const auto& x = pts[i];
    std::vector<double> s(kBands, 0.0);
    for (int b = 0; b < kBands; ++b) s[b] = x[0] + 2 * x[1] + (b + 1) * x[2];
    ASSERT_TRUE(set->Add(static_cast<std::int64_t>(500 + i), x, s).ok());
  }
  const std::vector<double> mirrored = {pts[20][0], pts[20][1], -pts[20][2]};
  EXPECT_EQ(Make(set)->Evaluate(mirrored).status, InterpStatus::kOutsideHull);

  Options options;
  options.mirror_phi = true;
  auto interp = Make(set, options);
  ASSERT_NE(interp, nullptr);
  const Interpolation r = interp->Evaluate(mirrored);
  ASSERT_EQ(r.status, InterpStatus::kOk) << r.detail;
  const auto want = set->spectrum(20);
  ExpectNear(r.spectrum, std::vector<double>(want.begin(), want.end()), 1e-9);
  bool found = false;
  for (const Vertex& v : r.vertices) {
    if (v.weight > 0.999) {
      found = true;
      EXPECT_EQ(v.id, 520);  // the copy keeps its sample's id and index
      EXPECT_EQ(v.index, 20u);
      EXPECT_EQ(v.coords, mirrored);  // and reports where the copy is
    }
  }
  EXPECT_TRUE(found);
  // Three images per sample (φ, −φ, 360° − φ). The box's four φ = 0 corners coincide with their
  // −φ images, and their 360° − φ images with the four φ = 360° corners, whose 360° − φ images
  // coincide with the φ = 0 corners: 12 duplicates, the first (measured) of each kept once.
  EXPECT_EQ(interp->point_count(), 3 * pts.size() - 12);
}

TEST(Delaunay, ReciprocityAddsSwappedCopies) {
  // Samples only where θi <= θo; reciprocity fills θi > θo.
  std::mt19937_64 rng(23);
  const LinearField base = MakeField(3, rng);
  LinearField f = base;  // make it symmetric in θi ↔ θo so the copies are consistent
  for (int b = 0; b < kBands; ++b) f.slope[b * 3 + 1] = f.slope[b * 3 + 0];
  std::vector<std::vector<double>> pts = {{0, 0, 0},   {0, 90, 0},   {90, 90, 0},
                                          {0, 0, 360}, {0, 90, 360}, {90, 90, 360}};
  while (pts.size() < 400) {
    auto x = RandomPoint(3, rng);
    if (x[0] <= x[1]) pts.push_back(x);
  }
  auto set = SamplesOf(pts, f);
  const std::vector<double> query = {70, 20, 100};
  EXPECT_EQ(Make(set)->Evaluate(query).status, InterpStatus::kOutsideHull);
  Options options;
  options.reciprocity = true;
  auto interp = Make(set, options);
  ASSERT_NE(interp, nullptr);
  const Interpolation r = interp->Evaluate(query);
  ASSERT_EQ(r.status, InterpStatus::kOk) << r.detail;
  ExpectNear(r.spectrum, f.At(query), 1e-9);
  ExpectValidBlend(r, *set);
}

TEST(Delaunay, AxisScaleChangesTheMetricNotTheAnswersUnits) {
  std::mt19937_64 rng(29);
  const LinearField f = MakeField(3, rng);
  const auto pts = BoxCloud(3, 1000, rng);
  auto set = SamplesOf(pts, f);
  Options options;
  options.axis_scale = {4.0, 4.0, 1.0};  // θ weighs as much as φ
  auto scaled = Make(set, options);
  auto plain = Make(set);
  ASSERT_NE(scaled, nullptr);
  ASSERT_NE(plain, nullptr);
  int different_vertices = 0;
  for (int q = 0; q < 1000; ++q) {
    const auto x = RandomPoint(3, rng);
    const Interpolation a = scaled->Evaluate(x);
    const Interpolation b = plain->Evaluate(x);
    ASSERT_EQ(a.status, InterpStatus::kOk) << a.detail;
    ExpectNear(a.spectrum, f.At(x), 1e-9);
    for (const Vertex& v : a.vertices) EXPECT_EQ(v.coords, pts[v.index]);  // unscaled
    auto ids = [](const Interpolation& r) {
      std::vector<std::int64_t> out;
      for (const Vertex& v : r.vertices) out.push_back(v.id);
      std::sort(out.begin(), out.end());
      return out;
    };
    if (ids(a) != ids(b)) ++different_vertices;
  }
  EXPECT_GT(different_vertices, 100);  // a different metric, a different triangulation
}

TEST(Delaunay, HintedAndBatchedQueriesMatchPlainOnes) {
  std::mt19937_64 rng(31);
  const LinearField f = MakeField(3, rng);
  auto set = SamplesOf(BoxCloud(3, 2000, rng), f);
  auto interp = Make(set);
  ASSERT_NE(interp, nullptr);
  // A slow sweep (consecutive queries close together) with a few far jumps and outside points.
  std::vector<double> queries;
  for (int q = 0; q < 2000; ++q) {
    const double t = q / 2000.0;
    std::vector<double> x = {90 * t, 45 + 40 * std::sin(20 * t), 360 * (1 - t)};
    if (q % 100 == 0) x = RandomPoint(3, rng);
    if (q % 333 == 0) x[2] = 400;
    queries.insert(queries.end(), x.begin(), x.end());
  }
  std::vector<Interpolation> batch;
  ASSERT_TRUE(interp->EvaluateBatch(queries, batch).ok());
  ASSERT_EQ(batch.size(), 2000u);
  LocateHint hint;
  for (std::size_t q = 0; q < batch.size(); ++q) {
    const std::span<const double> x(queries.data() + 3 * q, 3);
    const Interpolation plain = interp->Evaluate(x);
    const Interpolation hinted = interp->EvaluateFrom(x, hint);
    ASSERT_EQ(batch[q].status, plain.status) << "query " << q;
    ASSERT_EQ(hinted.status, plain.status) << "query " << q;
    if (plain.status != InterpStatus::kOk) continue;
    ExpectNear(batch[q].spectrum, plain.spectrum, 1e-9);
    ExpectNear(hinted.spectrum, plain.spectrum, 1e-9);
    ExpectNear(plain.spectrum, f.At(x), 1e-9);
  }
  // Hints that are not simplices at all cost nothing but time.
  for (std::int32_t bad : {-7, 1 << 30}) {
    LocateHint h{bad};
    EXPECT_EQ(interp->EvaluateFrom(std::span<const double>(queries.data() + 3, 3), h).status,
              InterpStatus::kOk);
  }
  EXPECT_FALSE(interp->EvaluateBatch(std::span<const double>(queries.data(), 5), batch).ok());
}

TEST(Delaunay, SpectrumOnlyQueriesMatchFullAnswers) {
  std::mt19937_64 rng(47);
  const LinearField f = MakeField(3, rng);
  auto set = SamplesOf(BoxCloud(3, 1000, rng), f);
  auto interp = Make(set);
  ASSERT_NE(interp, nullptr);
  LocateHint hint;
  std::vector<double> spectrum(kBands);
  for (int q = 0; q < 1000; ++q) {
    auto x = RandomPoint(3, rng);
    if (q % 10 == 0) x[1] = 95;  // beyond the box: outside
    const Interpolation full = interp->Evaluate(x);
    std::fill(spectrum.begin(), spectrum.end(), -1.0);
    const InterpStatus status = interp->EvaluateSpectrum(x, spectrum, hint);
    ASSERT_EQ(status, full.status) << "query " << q;
    if (status == InterpStatus::kOk) {
      EXPECT_EQ(spectrum, full.spectrum);  // the same blend, bit for bit
    } else {
      EXPECT_EQ(spectrum, std::vector<double>(kBands, -1.0));  // untouched
    }
  }
  std::vector<double> short_spectrum(kBands - 1);
  EXPECT_EQ(interp->EvaluateSpectrum(RandomPoint(3, rng), short_spectrum, hint),
            InterpStatus::kOutsideHull);
}

TEST(Delaunay, ConcurrentQueriesGiveTheSequentialAnswers) {
  std::mt19937_64 rng(37);
  const LinearField f = MakeField(3, rng);
  auto set = SamplesOf(BoxCloud(3, 2000, rng), f);
  auto interp = Make(set);
  ASSERT_NE(interp, nullptr);
  std::vector<std::vector<double>> queries;
  for (int q = 0; q < 4000; ++q) queries.push_back(RandomPoint(3, rng));
  std::vector<std::vector<double>> expected;
  for (const auto& x : queries) expected.push_back(interp->Evaluate(x).spectrum);
  std::vector<int> mismatches(4, 0);
  std::vector<std::thread> threads;
  for (int t = 0; t < 4; ++t) {
    threads.emplace_back([&, t] {
      LocateHint hint;
      for (std::size_t q = static_cast<std::size_t>(t); q < queries.size(); q += 2) {
        const Interpolation r =
            t % 2 == 0 ? interp->Evaluate(queries[q]) : interp->EvaluateFrom(queries[q], hint);
        for (std::size_t b = 0; b < r.spectrum.size(); ++b) {
          if (std::abs(r.spectrum[b] - expected[q][b]) > 1e-9 * (1 + std::abs(expected[q][b]))) {
            ++mismatches[t];
          }
        }
      }
    });
  }
  for (auto& th : threads) th.join();
  for (int t = 0; t < 4; ++t) EXPECT_EQ(mismatches[t], 0) << "thread " << t;
}

TEST(Delaunay, RejectsInputsItCannotTriangulate) {
  auto make = [](std::shared_ptr<const SampleSet> set, Options options = {}) {
    return MakeDelaunayInterpolator(std::move(set), options);
  };
  auto null = make(nullptr);
  ASSERT_FALSE(null.ok());
  EXPECT_EQ(null.status().code(), StatusCode::kInvalidArgument);

  auto empty = make(std::make_shared<SampleSet>(3, kBands));
  ASSERT_FALSE(empty.ok());
  EXPECT_THAT(empty.status().message(), HasSubstr("empty"));

  const std::vector<double> s(kBands, 1.0);
  auto few = std::make_shared<SampleSet>(3, kBands);
  for (const auto& x : std::vector<std::vector<double>>{{0, 0, 0}, {1, 0, 0}, {0, 1, 0}}) {
    ASSERT_TRUE(few->Add(0, x, s).ok());
  }
  auto too_few = make(few);
  ASSERT_FALSE(too_few.ok());
  EXPECT_EQ(too_few.status().code(), StatusCode::kInvalidArgument);
  EXPECT_THAT(too_few.status().message(), HasSubstr("at least 4"));

  auto flat = std::make_shared<SampleSet>(3, kBands);  // all at φ = 30: a plane
  std::mt19937_64 rng(41);
  for (int i = 0; i < 50; ++i) {
    auto x = RandomPoint(3, rng);
    x[2] = 30;
    ASSERT_TRUE(flat->Add(i, x, s).ok());
  }
  auto planar = make(flat);
  ASSERT_FALSE(planar.ok());
  EXPECT_EQ(planar.status().code(), StatusCode::kInvalidArgument);
  EXPECT_THAT(planar.status().message(), HasSubstr("one plane"));

  auto ok_set = SamplesOf(BoxCloud(3, 20, rng), MakeField(3, rng));
  Options wrong_scale;
  wrong_scale.axis_scale = {1, 2};
  EXPECT_THAT(make(ok_set, wrong_scale).status().message(), HasSubstr("axis_scale"));
  Options zero_scale;
  zero_scale.axis_scale = {1, 0, 1};
  EXPECT_FALSE(make(ok_set, zero_scale).ok());

  auto four = SamplesOf(BoxCloud(4, 20, rng), MakeField(4, rng));
  Options mirror;
  mirror.mirror_phi = true;
  EXPECT_THAT(make(four, mirror).status().message(), HasSubstr("mirror_phi"));
  EXPECT_TRUE(make(four).ok());
}

TEST(Delaunay, AQueryOfTheWrongSizeIsNotAnswered) {
  std::mt19937_64 rng(43);
  auto interp = Make(SamplesOf(BoxCloud(3, 50, rng), MakeField(3, rng)));
  ASSERT_NE(interp, nullptr);
  const Interpolation r = interp->Evaluate(std::vector<double>{1, 2});
  EXPECT_NE(r.status, InterpStatus::kOk);
  EXPECT_TRUE(r.spectrum.empty());
  EXPECT_THAT(r.detail, HasSubstr("expected 3"));
}

}  // namespace
}  // namespace brdf::interp
