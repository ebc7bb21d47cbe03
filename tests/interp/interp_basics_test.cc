// The method-independent pieces: names and parsing, SampleSet::Add's checks, option validation,
// symmetry augmentation, the barycentric solver and the cube triangulations.
#include <gtest/gtest.h>

#include <cmath>
#include <set>

#include "core/interp/barycentric.h"
#include "core/interp/interpolator.h"
#include "core/interp/octant/cube.h"
#include "core/interp/search/point_cloud.h"

namespace brdf::interp {
namespace {

TEST(InterpNamesTest, MethodsAndStatusesRoundTrip) {
  for (Method m : {Method::kOctant, Method::kDelaunay, Method::kNearest}) {
    const Result<Method> parsed = ParseMethod(MethodName(m));
    ASSERT_TRUE(parsed.ok());
    EXPECT_EQ(*parsed, m);
  }
  const auto bad = ParseMethod("kriging");
  EXPECT_EQ(bad.status().code(), StatusCode::kInvalidArgument);
  EXPECT_NE(bad.status().message().find("kriging"), std::string::npos);
  std::set<std::string> names;
  for (InterpStatus s : {InterpStatus::kOk, InterpStatus::kEmptyOctant,
                         InterpStatus::kNoEnclosingSimplex, InterpStatus::kOutsideHull}) {
    names.insert(InterpStatusName(s));
  }
  EXPECT_EQ(names,
            (std::set<std::string>{"ok", "empty_octant", "no_enclosing_simplex", "outside_hull"}));
}

TEST(SampleSetTest, AddChecksShapesAndValues) {
  SampleSet set(3, 2);
  const double c[] = {1, 2, 3}, s[] = {0.5, 0.25};
  ASSERT_TRUE(set.Add(42, c, s).ok());
  EXPECT_EQ(set.size(), 1u);
  EXPECT_EQ(set.id(0), 42);
  EXPECT_EQ(set.coords(0)[2], 3);
  EXPECT_EQ(set.spectrum(0)[1], 0.25);

  const double c2[] = {1, 2}, s3[] = {1, 2, 3};
  EXPECT_EQ(set.Add(1, c2, s).code(), StatusCode::kInvalidArgument);
  EXPECT_EQ(set.Add(1, c, s3).code(), StatusCode::kInvalidArgument);
  const double nan_c[] = {1, NAN, 3}, inf_s[] = {INFINITY, 1};
  const Status a = set.Add(7, nan_c, s);
  EXPECT_EQ(a.code(), StatusCode::kInvalidArgument);
  EXPECT_NE(a.message().find("id 7"), std::string::npos) << a.message();
  EXPECT_EQ(set.Add(1, c, inf_s).code(), StatusCode::kInvalidArgument);
  EXPECT_EQ(set.size(), 1u);  // nothing half-added

  SampleSet flat(2, 2);
  EXPECT_EQ(flat.Add(1, c2, s).code(), StatusCode::kInvalidArgument);
}

TEST(OptionsTest, BadOptionsNameTheOption) {
  Options o;
  EXPECT_TRUE(ValidateOptions(o, 3).ok());
  EXPECT_TRUE(ValidateOptions(o, 4).ok());
  EXPECT_FALSE(ValidateOptions(o, 2).ok());
  o.axis_scale = {1, 1};
  Status s = ValidateOptions(o, 3);
  EXPECT_EQ(s.code(), StatusCode::kInvalidArgument);
  EXPECT_NE(s.message().find("axis_scale"), std::string::npos);
  for (double bad : std::initializer_list<double>{0.0, -1.0, NAN, INFINITY}) {
    o.axis_scale = {1, bad, 1};
    s = ValidateOptions(o, 3);
    EXPECT_EQ(s.code(), StatusCode::kInvalidArgument);
    EXPECT_NE(s.message().find("axis_scale"), std::string::npos);
  }
  o.axis_scale = {1, 2, 0.5, 3};
  EXPECT_TRUE(ValidateOptions(o, 4).ok());
  o = {};
  o.mirror_phi = true;
  EXPECT_TRUE(ValidateOptions(o, 3).ok());
  s = ValidateOptions(o, 4);
  EXPECT_NE(s.message().find("mirror_phi"), std::string::npos);
  o = {};
  o.reciprocity = true;
  s = ValidateOptions(o, 4);
  EXPECT_NE(s.message().find("reciprocity"), std::string::npos);
}

TEST(PointCloudTest, CopiesRankAfterMeasuredSamples) {
  SampleSet set(3, 1);
  const double a[] = {10, 20, 30}, b[] = {40, 50, 0}, v[] = {1};
  ASSERT_TRUE(set.Add(1, a, v).ok());
  ASSERT_TRUE(set.Add(2, b, v).ok());
  Options o;
  o.mirror_phi = true;
  o.reciprocity = true;
  o.axis_scale = {1, 2, 0.5};
  const Result<PointCloud> cloud = BuildPointCloud(set, o);
  ASSERT_TRUE(cloud.ok());
  // Images in blocks: measured, −φ, 360° − φ, then the same three swapped (θi ↔ θo).
  ASSERT_EQ(cloud->size(), 12u);
  const std::vector<std::vector<double>> expected = {
      {10, 20, 30}, {40, 50, 0}, {10, 20, -30}, {40, 50, 0}, {10, 20, 330}, {40, 50, 360},
      {20, 10, 30}, {50, 40, 0}, {20, 10, -30}, {50, 40, 0}, {20, 10, 330}, {50, 40, 360}};
  for (std::size_t r = 0; r < 12; ++r) {
    const auto p = cloud->point(r);
    EXPECT_EQ(std::vector<double>(p.begin(), p.end()), expected[r]) << r;
    EXPECT_EQ(cloud->sample[r], r % 2);
    EXPECT_EQ(cloud->scaled_point(r)[1], 2 * expected[r][1]);
    EXPECT_FALSE(std::signbit(p[2]) && p[2] == 0) << "mirrored 0 stays +0";
  }
  EXPECT_FALSE(BuildPointCloud(SampleSet(3, 1), {}).ok());
}

TEST(BarycentricTest, WeightsInsideOutsideAndFlat) {
  const double v0[] = {0, 0, 0}, v1[] = {4, 0, 0}, v2[] = {0, 4, 0}, v3[] = {0, 0, 4};
  const double* tet[] = {v0, v1, v2, v3};
  const double inside[] = {1, 1, 1};
  BarycentricWeights w = Barycentric(tet, inside, 3);
  ASSERT_EQ(w.fit, SimplexFit::kEncloses);
  EXPECT_DOUBLE_EQ(w.weights[0], 0.25);
  EXPECT_DOUBLE_EQ(w.weights[3], 0.25);
  const double outside[] = {3, 3, 3};
  EXPECT_EQ(Barycentric(tet, outside, 3).fit, SimplexFit::kOutside);
  // Orientation does not matter.
  const double* flipped[] = {v0, v2, v1, v3};
  w = Barycentric(flipped, inside, 3);
  EXPECT_EQ(w.fit, SimplexFit::kEncloses);
  // On a face: weight exactly 0, still enclosed; at a vertex: exactly one-hot.
  const double on_face[] = {2, 2, 0};
  w = Barycentric(tet, on_face, 3);
  ASSERT_EQ(w.fit, SimplexFit::kEncloses);
  EXPECT_EQ(w.weights[3], 0.0);
  w = Barycentric(tet, v2, 3);
  ASSERT_EQ(w.fit, SimplexFit::kEncloses);
  EXPECT_EQ(w.weights[0], 0.0);
  EXPECT_EQ(w.weights[2], 1.0);
  // Flat (coplanar) and collapsed (repeated vertex) tetrahedra are degenerate.
  const double flat3[] = {2, 2, 0};
  const double* flat[] = {v0, v1, v2, flat3};
  EXPECT_EQ(Barycentric(flat, on_face, 3).fit, SimplexFit::kDegenerate);
  const double* collapsed[] = {v0, v1, v1, v3};
  EXPECT_EQ(Barycentric(collapsed, inside, 3).fit, SimplexFit::kDegenerate);
}

TEST(BarycentricTest, FourDimensionsAndBlend) {
  const double v0[] = {0, 0, 0, 0}, v1[] = {1, 0, 0, 0}, v2[] = {0, 1, 0, 0}, v3[] = {0, 0, 1, 0},
               v4[] = {0, 0, 0, 1};
  const double* s[] = {v0, v1, v2, v3, v4};
  const double p[] = {0.1, 0.2, 0.3, 0.15};
  const BarycentricWeights w = Barycentric(s, p, 4);
  ASSERT_EQ(w.fit, SimplexFit::kEncloses);
  EXPECT_NEAR(w.weights[0], 0.25, 1e-15);
  EXPECT_NEAR(w.weights[3], 0.3, 1e-15);
  const double q[] = {0.5, 0.5, 0.5, 0.5};
  EXPECT_EQ(Barycentric(s, q, 4).fit, SimplexFit::kOutside);

  const double a[] = {1, 10}, b[] = {3, 30};
  const double* spectra[] = {a, b};
  const double weights[] = {0.25, 0.75};
  double out[2];
  BlendSpectra(weights, spectra, out);
  EXPECT_DOUBLE_EQ(out[0], 2.5);
  EXPECT_DOUBLE_EQ(out[1], 25);
}

TEST(CubeTest, LettersAndTriangulations) {
  // The letters of interpolation.md: + means coordinate >= the query's, axes (θi, θo, φ).
  const std::string letters = "ABCDEFGH";
  const int signs[8][3] = {{0, 0, 0}, {1, 0, 0}, {1, 1, 0}, {0, 1, 0},
                           {0, 0, 1}, {1, 0, 1}, {1, 1, 1}, {0, 1, 1}};
  for (int k = 0; k < 8; ++k) {
    const double p[] = {0, 0, 0};
    const double x[] = {signs[k][0] ? 0.0 : -1.0, signs[k][1] ? 2.0 : -1.0,
                        signs[k][2] ? 3.0 : -1.0};
    EXPECT_EQ(OctantLetter(OrthantOf(x, p, 3)), letters[static_cast<std::size_t>(k)]);
  }
  std::vector<std::string> tets;
  for (std::size_t s = 0; s < CubeSimplices(3).size(); ++s) {
    tets.push_back(SimplexName(static_cast<int>(s), 3));
  }
  EXPECT_EQ(tets,
            (std::vector<std::string>{"tetrahedron ABCF", "tetrahedron ACDH", "tetrahedron AEFH",
                                      "tetrahedron CFGH", "tetrahedron ACFH"}));
  // Kuhn: 24 distinct simplices, each a monotone path from corner 0 to corner 15.
  const auto kuhn = CubeSimplices(4);
  ASSERT_EQ(kuhn.size(), 24u);
  std::set<std::vector<int>> distinct;
  for (const CubeSimplex& s : kuhn) {
    EXPECT_EQ(s.corners[0], 0);
    EXPECT_EQ(s.corners[4], 15);
    for (int k = 0; k < 4; ++k) {
      const int step = s.corners[k + 1] ^ s.corners[k];
      EXPECT_EQ(step & (step - 1), 0);    // one bit
      EXPECT_EQ(s.corners[k] & step, 0);  // that was not set yet
    }
    distinct.insert({s.corners, s.corners + 5});
  }
  EXPECT_EQ(distinct.size(), 24u);
  EXPECT_EQ(SimplexName(0, 4), "Kuhn simplex 0 of 24 (corners 0-1-3-7-15)");
}

}  // namespace
}  // namespace brdf::interp
