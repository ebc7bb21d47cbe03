// NearDelaunay: the Delaunay method's answer at a query from a triangulation of the points near
// it, given only when proved to be the whole triangulation's (core/interp/delaunay/near.h).
#include <gtest/gtest.h>

#include <cmath>
#include <cstddef>
#include <memory>
#include <optional>
#include <random>
#include <vector>

#include "core/interp/delaunay/delaunay.h"
#include "core/interp/delaunay/near.h"
#include "core/interp/interpolator.h"
#include "tests/interp/interp_test_data.h"

namespace brdf::interp {
namespace {

using testing::AnalyticSpectrum;
using testing::MakeSamples;
using testing::PaperGrid;
using testing::Point;
using testing::RandomPoints;

struct Compared {
  std::size_t answered = 0;  // kOk here
  std::size_t outside = 0;   // kOutsideHull here
  std::size_t inside = 0;    // kOk from the whole triangulation
};

// Every query's NearDelaunay answer, when it gives one, against the whole triangulation's: the
// same status, and the same spectrum up to rounding (the same simplex: near.h).
Compared CompareWithWhole(const std::shared_ptr<const SampleSet>& set, const Options& options,
                          const std::vector<Point>& queries) {
  Result<NearDelaunay> near = NearDelaunay::Create(set, options);
  EXPECT_TRUE(near.ok()) << near.status().ToString();
  Result<std::unique_ptr<DelaunayInterpolator>> whole = DelaunayInterpolator::Create(set, options);
  EXPECT_TRUE(whole.ok()) << whole.status().ToString();
  Compared c;
  if (!near.ok() || !whole.ok()) return c;
  EXPECT_EQ(near->point_count(), (*whole)->point_count());
  const auto bands = static_cast<std::size_t>(set->bands());
  for (const Point& q : queries) {
    std::vector<double> got(bands, -1.0);
    std::vector<double> want(bands, -2.0);
    const InterpStatus whole_status = (*whole)->SpectrumAt(q, want);
    if (whole_status == InterpStatus::kOk) ++c.inside;
    const std::optional<InterpStatus> status = near->SpectrumAt(q, got);
    if (!status) continue;
    EXPECT_EQ(*status, whole_status) << "query " << q[0] << ", " << q[1] << ", " << q[2];
    if (*status != whole_status) continue;
    if (*status == InterpStatus::kOutsideHull) {
      ++c.outside;
      continue;
    }
    ++c.answered;
    for (std::size_t b = 0; b < bands; ++b) {
      EXPECT_NEAR(got[b], want[b], 1e-12 * (1 + std::abs(want[b])))
          << "band " << b << " at " << q[0] << ", " << q[1] << ", " << q[2];
    }
  }
  return c;
}

Options Mirrored() {
  Options options;
  options.mirror_phi = true;
  options.reciprocity = true;
  return options;
}

TEST(NearDelaunay, AnswersAsTheWholeTriangulationOnRandomPoints) {
  const std::vector<Point> points = RandomPoints(3000, {0, 0, 0}, {90, 90, 180}, 7);
  const auto set = MakeSamples(points, AnalyticSpectrum(3));
  const std::vector<Point> queries = RandomPoints(300, {-5, -5, -10}, {95, 95, 190}, 8);
  const Compared c = CompareWithWhole(set, Mirrored(), queries);
  // Near the data almost every query is proved from a small neighbourhood.
  EXPECT_GE(c.answered, c.inside * 9 / 10);
  EXPECT_GT(c.inside, 100u);
  EXPECT_GT(c.outside, 10u);  // the queries beyond the points' bounding box
}

TEST(NearDelaunay, AnswersAsTheWholeTriangulationOnTheRigGridWithItsCosphericalPoses) {
  const auto set = MakeSamples(PaperGrid(), AnalyticSpectrum(3));
  std::vector<Point> queries = RandomPoints(60, {0, 0, 0}, {90, 90, 180}, 9);
  queries.push_back({45, 0, 0});  // the sample colour's 45°:0° geometry, on the data's edge
  queries.push_back({0, 45, 0});
  queries.push_back({89.9, 30, 120});
  const Compared c = CompareWithWhole(set, Mirrored(), queries);
  EXPECT_GE(c.answered, c.inside * 8 / 10);
  EXPECT_GT(c.inside, 40u);
}

TEST(NearDelaunay, AnswersTheColourGeometryOnTheReadingsEdge) {
  // Jittered rig poses, as a large session has them: 45°:0° has no octant value (θo = 0 is the
  // edge) but lies inside the mirrored and swapped points' hull.
  std::vector<Point> points = PaperGrid();
  std::mt19937_64 rng(3);
  std::normal_distribution<double> jitter(0, 0.2);
  for (Point& p : points) {
    for (double& v : p) v = std::max(0.0, v + jitter(rng));
  }
  const auto set = MakeSamples(points, AnalyticSpectrum(3));
  const Compared c = CompareWithWhole(set, Mirrored(), {{45, 0, 0}});
  EXPECT_EQ(c.inside, 1u);
  EXPECT_EQ(c.answered, 1u);
}

TEST(NearDelaunay, AQueryBeyondTheBoundingBoxIsOutsideWithoutTriangulating) {
  const std::vector<Point> points = RandomPoints(500, {0, 0, 0}, {80, 80, 180}, 11);
  const auto set = MakeSamples(points, AnalyticSpectrum(3));
  Result<NearDelaunay> near = NearDelaunay::Create(set, Mirrored());
  ASSERT_TRUE(near.ok()) << near.status().ToString();
  std::vector<double> out(static_cast<std::size_t>(set->bands()), 7.0);
  for (const Point& q :
       std::vector<Point>{{89.8, 10, 30}, {10, 85, 30}, {10, 10, 400}, {10, 10, -200}}) {
    EXPECT_EQ(near->SpectrumAt(q, out, 4), InterpStatus::kOutsideHull);
  }
  EXPECT_EQ(near->SpectrumAt(std::vector<double>{NAN, 10, 30}, out), InterpStatus::kOutsideHull);
  EXPECT_EQ(out[0], 7.0);  // untouched
}

TEST(NearDelaunay, AQueryBeyondTheHullInsideTheBoundingBoxIsOutside) {
  // Points in a ball: a corner of their bounding box is inside the box, outside the hull, and
  // nowhere near a neighbourhood's hull: only the convex hull's planes can prove it.
  std::vector<Point> points;
  for (const Point& p : RandomPoints(4000, {-1, -1, -1}, {1, 1, 1}, 16)) {
    if (p[0] * p[0] + p[1] * p[1] + p[2] * p[2] < 1) {
      points.push_back({50 + 30 * p[0], 50 + 30 * p[1], 90 + 60 * p[2]});
    }
  }
  const auto set = MakeSamples(points, AnalyticSpectrum(3));
  Result<NearDelaunay> near = NearDelaunay::Create(set, Options{});
  ASSERT_TRUE(near.ok()) << near.status().ToString();
  std::vector<double> out(static_cast<std::size_t>(set->bands()), 7.0);
  const Point corner{25, 25, 40};
  EXPECT_EQ(near->SpectrumAt(corner, out, 4), InterpStatus::kOutsideHull);
  EXPECT_EQ(out[0], 7.0);
  const Compared c = CompareWithWhole(set, Options{}, {corner, {50, 50, 90}, {21, 50, 90}});
  EXPECT_EQ(c.outside, 1u);
  EXPECT_EQ(c.answered, 2u);  // the centre and a query just inside the ball
}

TEST(NearDelaunay, SaysNothingWhenTheNeighbourhoodCannotProveIt) {
  // Inside the whole hull but outside the hull of any 64 points near it: nothing proved from so
  // few points (the caller builds the whole triangulation), the answer from all of them.
  std::vector<Point> points = RandomPoints(400, {0, 0, 0}, {10, 10, 10}, 12);
  for (const Point& p : RandomPoints(400, {80, 80, 170}, {90, 90, 180}, 13)) points.push_back(p);
  const auto set = MakeSamples(points, AnalyticSpectrum(3));
  Result<NearDelaunay> near = NearDelaunay::Create(set, Options{});
  ASSERT_TRUE(near.ok()) << near.status().ToString();
  std::vector<double> out(static_cast<std::size_t>(set->bands()), 0.0);
  const Point middle{30, 30, 58};  // on the line between the clusters, nearer the first
  EXPECT_EQ(near->SpectrumAt(middle, out, 64), std::nullopt);
  EXPECT_EQ(near->SpectrumAt(middle, out), std::optional<InterpStatus>(InterpStatus::kOk));
  const Compared c = CompareWithWhole(set, Options{}, {middle});
  EXPECT_EQ(c.answered, 1u);
}

TEST(NearDelaunay, RefusesAnisotropicSamples) {
  const auto set =
      MakeSamples(RandomPoints(50, {0, 0, 0, 0}, {80, 360, 80, 360}, 14), AnalyticSpectrum(4));
  Result<NearDelaunay> near = NearDelaunay::Create(set, Options{});
  ASSERT_FALSE(near.ok());
  EXPECT_NE(near.status().message().find("3D"), std::string::npos) << near.status().message();
}

TEST(NearDelaunay, RefusesOptionsAnsweredThroughAnotherInterpolator) {
  const auto set = MakeSamples(RandomPoints(50, {0, 0, 0}, {80, 80, 180}, 15), AnalyticSpectrum(3));
  Options half;
  half.coordinates = Coordinates::kHalfDifference;
  Options trend;
  trend.trend = Trend::kBivariate;
  for (const Options& options : {half, trend}) {
    Result<NearDelaunay> near = NearDelaunay::Create(set, options);
    ASSERT_FALSE(near.ok());
    EXPECT_EQ(near.status().code(), StatusCode::kInvalidArgument);
  }
}

}  // namespace
}  // namespace brdf::interp
