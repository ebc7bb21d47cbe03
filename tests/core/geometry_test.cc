#include "core/geometry.h"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <numbers>
#include <set>
#include <vector>

namespace brdf {
namespace {

using ::testing::HasSubstr;

constexpr double kRad = std::numbers::pi / 180.0;
constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();

double CosD(double deg) {
  return std::cos(deg * kRad);
}
double SinD(double deg) {
  return std::sin(deg * kRad);
}

std::vector<IsoDirection> IsoPointsOf(const std::vector<Pose>& poses,
                                      const HolderConvention& convention = {}) {
  std::vector<IsoDirection> out;
  for (const Pose& p : poses) out.push_back(ToIsotropic(PoseToDirections(p, convention)));
  return out;
}

TEST(GeometryTest, ForwardMatchesClosedForms) {
  for (double alpha = 0; alpha <= 80; alpha += 10) {
    for (double beta = -175; beta <= 180; beta += 12.5) {
      for (double delta = 0; delta <= 180; delta += 15) {
        const Directions d = PoseToDirections({alpha, beta, 0, delta});
        SCOPED_TRACE(::testing::Message()
                     << "alpha " << alpha << " beta " << beta << " delta " << delta);
        EXPECT_NEAR(CosD(d.theta_i), CosD(alpha) * CosD(beta), 1e-12);
        EXPECT_NEAR(CosD(d.theta_o), CosD(alpha) * CosD(beta - delta), 1e-12);
        EXPECT_NEAR(CosD(delta),
                    CosD(d.theta_i) * CosD(d.theta_o) +
                        SinD(d.theta_i) * SinD(d.theta_o) * CosD(d.phi_o - d.phi_i),
                    1e-12);
        // α ≥ 0 only reaches relative azimuths in [0°, 180°]: n·(L×V) = sin α sin δ ≥ 0.
        EXPECT_GE(SinD(d.theta_i) * SinD(d.theta_o) * SinD(d.phi_o - d.phi_i), -1e-12);
        EXPECT_GT(d.phi_i, -180.0);
        EXPECT_LE(d.phi_i, 180.0);
        EXPECT_GT(d.phi_o, -180.0);
        EXPECT_LE(d.phi_o, 180.0);
      }
    }
  }
}

TEST(GeometryTest, KnownPoses) {
  // At rest the sample faces the lamp.
  Directions d = PoseToDirections({0, 0, 0, 0});
  EXPECT_DOUBLE_EQ(d.theta_i, 0);
  EXPECT_DOUBLE_EQ(d.theta_o, 0);
  // A pure turn by β with the detector at δ = 2β is the mirror (specular) configuration.
  IsoDirection iso = ToIsotropic(PoseToDirections({0, 30, 0, 60}));
  EXPECT_NEAR(iso.theta_i, 30, 1e-12);
  EXPECT_NEAR(iso.theta_o, 30, 1e-12);
  EXPECT_NEAR(iso.phi, 180, 1e-12);
  // Detector back at the lamp: retro side.
  iso = ToIsotropic(PoseToDirections({0, 30, 0, 0}));
  EXPECT_NEAR(iso.theta_o, 30, 1e-12);
  EXPECT_NEAR(iso.phi, 0, 1e-12);
  // Normal incidence: the azimuth is undefined and set to 0.
  iso = ToIsotropic(PoseToDirections({0, 0, 0, 40}));
  EXPECT_NEAR(iso.theta_i, 0, 1e-12);
  EXPECT_NEAR(iso.theta_o, 40, 1e-12);
  EXPECT_EQ(iso.phi, 0);
  // Lamp direction in the sample frame: (L·t, L·b, L·n) = (−sin β, −sin α cos β, cos α cos β).
  d = PoseToDirections({20, 0, 0, 0});
  EXPECT_NEAR(d.theta_i, 20, 1e-12);
  EXPECT_NEAR(d.phi_i, -90, 1e-12);
  d = PoseToDirections({0, 25, 0, 0});
  EXPECT_NEAR(d.phi_i, 180, 1e-12);
}

TEST(GeometryTest, GammaShiftsBothAzimuthsTogether) {
  for (double gamma : {15.0, -40.0, 90.0, 170.0}) {
    const Directions d0 = PoseToDirections({35, 20, 0, 70});
    const Directions d = PoseToDirections({35, 20, gamma, 70});
    EXPECT_NEAR(d.theta_i, d0.theta_i, 1e-12);
    EXPECT_NEAR(d.theta_o, d0.theta_o, 1e-12);
    EXPECT_NEAR(std::remainder(d.phi_i - (d0.phi_i - gamma), 360.0), 0, 1e-9);
    EXPECT_NEAR(std::remainder(d.phi_o - (d0.phi_o - gamma), 360.0), 0, 1e-9);
    const IsoDirection a = ToIsotropic(d), b = ToIsotropic(d0);
    EXPECT_NEAR(a.phi, b.phi, 1e-9);
  }
}

TEST(GeometryTest, ToIsotropicFoldsRelativeAzimuth) {
  EXPECT_NEAR(ToIsotropic({30, 170, 40, -170}).phi, 20, 1e-12);
  EXPECT_NEAR(ToIsotropic({30, -90, 40, 90}).phi, 180, 1e-12);
  EXPECT_NEAR(ToIsotropic({30, 10, 40, 60}).phi, 50, 1e-12);
  EXPECT_NEAR(ToIsotropic({30, 60, 40, 10}).phi, 50, 1e-12);
  EXPECT_EQ(ToIsotropic({0, 60, 40, 10}).phi, 0);
  EXPECT_EQ(ToIsotropic({30, 60, 0, 10}).phi, 0);
}

TEST(GeometryTest, InverseThenForwardReturnsTheTarget) {
  std::vector<IsoDirection> targets;
  for (double ti = 0; ti <= 90; ti += 2.5)
    for (double to = 0; to <= 90; to += 2.5)
      for (double phi = 0; phi <= 180; phi += 7.5) targets.push_back({ti, to, phi});
  // Irregular values and near-degenerate ones (small δ, near the normal, grazing).
  for (double ti : {1e-6, 0.3, 17.123456, 44.9, 89.99, 90.0})
    for (double to : {1e-6, 0.3, 17.123457, 45.1, 89.999})
      for (double phi : {0.0, 1e-4, 0.77, 93.21, 179.9999, 180.0}) targets.push_back({ti, to, phi});
  for (const IsoDirection& x : targets) {
    SCOPED_TRACE(::testing::Message()
                 << "target " << x.theta_i << " " << x.theta_o << " " << x.phi);
    const Result<Pose> pose = InverseKinematics(x);
    ASSERT_TRUE(pose.ok()) << pose.status().ToString();
    EXPECT_EQ(pose->gamma, 0);
    EXPECT_GE(pose->alpha, 0);
    const IsoDirection y = ToIsotropic(PoseToDirections(*pose));
    EXPECT_NEAR(y.theta_i, x.theta_i, 1e-9);
    EXPECT_NEAR(y.theta_o, x.theta_o, 1e-9);
    // The azimuth is undefined (and reported as 0) at the normal, and ill-conditioned next to it:
    // a rounding error e in a direction's coordinates moves φ by e / sin θ. So φ itself is held to
    // 1e-9° from 0.01° off the normal, and everywhere the displacement on the unit sphere that
    // the φ error causes, sin θ · Δφ, is held to 1e-9°.
    const double min_theta = std::min(x.theta_i, x.theta_o);
    if (min_theta >= kNormalThetaEpsilonDeg) {
      EXPECT_LE(SinD(min_theta) * std::fabs(y.phi - x.phi), 1e-9);
    }
    if (min_theta >= 0.01) {
      EXPECT_NEAR(y.phi, x.phi, 1e-9);
    }
  }
}

TEST(GeometryTest, InverseKinematicsMatchesClosedForm) {
  const IsoDirection x{40, 55, 120};
  const Result<Pose> pose = InverseKinematics(x);
  ASSERT_TRUE(pose.ok());
  const double cos_delta =
      CosD(x.theta_i) * CosD(x.theta_o) + SinD(x.theta_i) * SinD(x.theta_o) * CosD(x.phi);
  const double delta = std::acos(cos_delta);
  const double c_cos_beta = CosD(x.theta_i);
  const double c_sin_beta = (CosD(x.theta_o) - CosD(x.theta_i) * cos_delta) / std::sin(delta);
  EXPECT_NEAR(pose->delta, delta / kRad, 1e-9);
  EXPECT_NEAR(pose->alpha, std::acos(std::hypot(c_cos_beta, c_sin_beta)) / kRad, 1e-9);
  EXPECT_NEAR(pose->beta, std::atan2(c_sin_beta, c_cos_beta) / kRad, 1e-9);
  // The degenerate choices documented in the header.
  const Result<Pose> same = InverseKinematics({35, 35, 0});
  ASSERT_TRUE(same.ok());
  EXPECT_EQ(*same, (Pose{0, 35, 0, 0}));
}

TEST(GeometryTest, InverseKinematicsRejectsBadTargets) {
  const std::pair<IsoDirection, const char*> cases[] = {
      {{kNaN, 10, 10}, "theta_i"}, {{10, 95, 10}, "theta_o"}, {{10, 10, 190}, "phi"},
      {{-1, 10, 10}, "theta_i"},   {{10, 10, -5}, "phi"},     {{10, kNaN, 0}, "theta_o"}};
  for (const auto& [target, field] : cases) {
    const Result<Pose> r = InverseKinematics(target);
    ASSERT_FALSE(r.ok()) << field;
    EXPECT_EQ(r.status().code(), StatusCode::kInvalidArgument);
    EXPECT_THAT(r.status().message(), HasSubstr(field));
  }
}

TEST(GeometryTest, InverseKinematicsHonoursLimits) {
  // This point needs α = 80°.
  const IsoDirection steep = ToIsotropic(PoseToDirections({80, 0, 0, 30}));
  ASSERT_TRUE(InverseKinematics(steep).ok());
  PoseLimits limits;
  limits.alpha_max_deg = 70;
  Result<Pose> r = InverseKinematics(steep, {}, limits);
  ASSERT_FALSE(r.ok());
  EXPECT_EQ(r.status().code(), StatusCode::kInvalidArgument);
  EXPECT_THAT(r.status().message(), HasSubstr("alpha"));
  // Mirror at 60° needs δ = 120°.
  limits = PoseLimits{};
  limits.delta_max_deg = 100;
  r = InverseKinematics({60, 60, 180}, {}, limits);
  ASSERT_FALSE(r.ok());
  EXPECT_THAT(r.status().message(), HasSubstr("delta"));
  limits.delta_max_deg = 150;
  r = InverseKinematics({60, 60, 180}, {}, limits);
  ASSERT_TRUE(r.ok());
  EXPECT_NEAR(r->delta, 120, 1e-9);
}

TEST(GeometryTest, ConventionMapsReadingsToModelAngles) {
  HolderConvention conv;
  conv.beta = {-1, 10};
  conv.alpha = {-1, 0};
  conv.delta = {1, 5};
  conv.gamma = {1, -30};
  // Readings (−20, −20, −30, 65) are model angles (20, 30, 0, 60).
  const Pose readings{-20, -20, -30, 65};
  EXPECT_EQ(ToModelAngles(readings, conv), (Pose{20, 30, 0, 60}));
  const Directions with = PoseToDirections(readings, conv);
  const Directions model = PoseToDirections({20, 30, 0, 60});
  EXPECT_DOUBLE_EQ(with.theta_i, model.theta_i);
  EXPECT_DOUBLE_EQ(with.theta_o, model.theta_o);
  EXPECT_DOUBLE_EQ(with.phi_i, model.phi_i);
  EXPECT_DOUBLE_EQ(with.phi_o, model.phi_o);
  // The same readings under the default convention are another geometry.
  EXPECT_GT(std::fabs(PoseToDirections(readings).theta_o - model.theta_o), 1);
  EXPECT_EQ(ToReadings(ToModelAngles(readings, conv), conv), readings);

  // Inverse kinematics answers in readings.
  const IsoDirection target{25, 50, 140};
  const Result<Pose> plain = InverseKinematics(target);
  const Result<Pose> mapped = InverseKinematics(target, conv);
  ASSERT_TRUE(plain.ok());
  ASSERT_TRUE(mapped.ok());
  EXPECT_EQ(*mapped, ToReadings(*plain, conv));
  const IsoDirection back = ToIsotropic(PoseToDirections(*mapped, conv));
  EXPECT_NEAR(back.theta_i, target.theta_i, 1e-9);
  EXPECT_NEAR(back.theta_o, target.theta_o, 1e-9);
  EXPECT_NEAR(back.phi, target.phi, 1e-9);
}

TEST(GeometryTest, ValidationNamesTheField) {
  HolderConvention conv;
  conv.gamma.sign = 0.5;
  Status s = ValidateConvention(conv);
  EXPECT_EQ(s.code(), StatusCode::kInvalidArgument);
  EXPECT_THAT(s.message(), HasSubstr("gamma"));
  conv = {};
  conv.delta.zero_deg = kNaN;
  EXPECT_THAT(ValidateConvention(conv).message(), HasSubstr("delta"));
  EXPECT_FALSE(InverseKinematics({10, 10, 10}, conv).ok());
  EXPECT_TRUE(ValidateConvention({}).ok());

  s = ValidatePose({0, kNaN, 0, 0});
  EXPECT_EQ(s.code(), StatusCode::kInvalidArgument);
  EXPECT_THAT(s.message(), HasSubstr("beta"));
  EXPECT_TRUE(ValidatePose({1, 2, 3, 4}).ok());
}

TEST(GeometryTest, IsValidChecksBothDirections) {
  EXPECT_TRUE(IsValid({10, 0, 89, 0}, 89.5));
  EXPECT_FALSE(IsValid({10, 0, 89.6, 0}, 89.5));
  EXPECT_FALSE(IsValid({89.6, 0, 10, 0}, 89.5));
  EXPECT_FALSE(IsValid({kNaN, 0, 10, 0}, 89.5));
}

TEST(GeometryTest, PaperGridHas2320PosesAnd2153Points) {
  const GridSpec spec;
  const Result<std::vector<Pose>> poses = ExpandSampleRotationGrid(spec);
  ASSERT_TRUE(poses.ok()) << poses.status().ToString();
  EXPECT_EQ(poses->size(), 2320u);
  const std::vector<IsoDirection> iso = IsoPointsOf(*poses);
  EXPECT_EQ(CountDistinctIsoPoints(iso), 2153u);

  std::set<double> deltas, alphas;
  for (const Pose& p : *poses) {
    deltas.insert(p.delta);
    alphas.insert(p.alpha);
    EXPECT_EQ(std::fmod(p.beta, 5.0), 0.0);
    EXPECT_GT(p.beta, -180);
    EXPECT_LE(p.beta, 180);
    EXPECT_TRUE(IsValid(PoseToDirections(p), spec.theta_max_deg));
  }
  EXPECT_EQ(deltas.size(), 14u);
  EXPECT_EQ(*deltas.rbegin(), 146.25);
  EXPECT_EQ(alphas.size(), 8u);
  // Every δ = 0 pose lies on the line θi = θo, φ = 0.
  for (std::size_t k = 0; k < poses->size(); ++k) {
    if ((*poses)[k].delta != 0) continue;
    EXPECT_NEAR(iso[k].theta_i, iso[k].theta_o, 1e-9);
    EXPECT_NEAR(iso[k].phi, 0, 1e-9);
  }
  // Measurement order: δ outer, α, β inner.
  for (std::size_t k = 1; k < poses->size(); ++k) {
    const Pose& a = (*poses)[k - 1];
    const Pose& b = (*poses)[k];
    ASSERT_LE(a.delta, b.delta);
    if (a.delta == b.delta) {
      ASSERT_LE(a.alpha, b.alpha);
      if (a.alpha == b.alpha) {
        ASSERT_LT(a.beta, b.beta);
      }
    }
  }
}

TEST(GeometryTest, GridMarginAndConventionChangeTheGrid) {
  GridSpec spec;
  spec.theta_max_deg = 90;  // grazing poses are now allowed
  Result<std::vector<Pose>> poses = ExpandSampleRotationGrid(spec);
  ASSERT_TRUE(poses.ok());
  EXPECT_GT(poses->size(), 2320u);
  spec.theta_max_deg = 60;
  poses = ExpandSampleRotationGrid(spec);
  ASSERT_TRUE(poses.ok());
  EXPECT_LT(poses->size(), 2320u);

  // Under a convention the grid is the same geometry in other readings.
  HolderConvention conv;
  conv.beta = {-1, 90};
  conv.delta = {1, 2.5};
  const Result<std::vector<Pose>> plain = ExpandSampleRotationGrid(GridSpec{});
  const Result<std::vector<Pose>> mapped = ExpandSampleRotationGrid(GridSpec{}, conv);
  ASSERT_TRUE(plain.ok());
  ASSERT_TRUE(mapped.ok());
  ASSERT_EQ(mapped->size(), plain->size());
  for (std::size_t k = 0; k < plain->size(); ++k) {
    EXPECT_EQ((*mapped)[k], ToReadings((*plain)[k], conv));
  }
  EXPECT_EQ(CountDistinctIsoPoints(IsoPointsOf(*mapped, conv)), 2153u);

  // Two dial positions double the poses, γ outermost.
  spec = GridSpec{};
  spec.gamma_deg = {0, 90};
  poses = ExpandSampleRotationGrid(spec);
  ASSERT_TRUE(poses.ok());
  ASSERT_EQ(poses->size(), 4640u);
  EXPECT_EQ(poses->front().gamma, 0);
  EXPECT_EQ(poses->back().gamma, 90);
}

TEST(GeometryTest, GridSpecValidationNamesTheField) {
  GridSpec spec;
  spec.delta_step_deg = 0;
  Result<std::vector<Pose>> r = ExpandSampleRotationGrid(spec);
  ASSERT_FALSE(r.ok());
  EXPECT_EQ(r.status().code(), StatusCode::kInvalidArgument);
  EXPECT_THAT(r.status().message(), HasSubstr("delta_step_deg"));
  spec = GridSpec{};
  spec.alpha_start_deg = 80;
  EXPECT_THAT(ValidateGridSpec(spec).message(), HasSubstr("alpha_start_deg"));
  spec = GridSpec{};
  spec.beta_step_deg = kNaN;
  EXPECT_THAT(ValidateGridSpec(spec).message(), HasSubstr("beta_step_deg"));
  spec = GridSpec{};
  spec.theta_max_deg = 95;
  EXPECT_THAT(ValidateGridSpec(spec).message(), HasSubstr("theta_max_deg"));
  spec = GridSpec{};
  spec.gamma_deg.clear();
  EXPECT_THAT(ValidateGridSpec(spec).message(), HasSubstr("gamma_deg"));
}

TEST(GeometryTest, GridWithNoValidPoseIsAnErrorNotAnEmptyList) {
  GridSpec spec;  // the plan_json fuzzer's grid: the detector at grazing or below at every pose
  spec.alpha_stop_deg = 0;
  spec.beta_step_deg = 90;
  spec.delta_start_deg = 90;
  EXPECT_TRUE(ValidateGridSpec(spec).ok());
  const Result<std::vector<Pose>> r = ExpandSampleRotationGrid(spec);
  ASSERT_FALSE(r.ok());
  EXPECT_EQ(r.status().code(), StatusCode::kInvalidArgument);
  EXPECT_THAT(r.status().message(), HasSubstr("no pose of the grid"));
  EXPECT_THAT(r.status().message(), HasSubstr("δ in [90°, 150°] and α in [0°, 0°]"));
  spec.delta_start_deg = 30;
  const Result<std::vector<Pose>> lower = ExpandSampleRotationGrid(spec);
  ASSERT_TRUE(lower.ok());
  EXPECT_FALSE(lower->empty());
}

TEST(GeometryTest, DistinctPointsUseTolerance) {
  const std::vector<IsoDirection> pts = {
      {10, 20, 30}, {10 + 1e-10, 20, 30}, {10, 20, 30 + 1e-7}, {40, 20, 30}, {10, 20 - 1e-10, 30}};
  const std::vector<IsoDirection> distinct = DistinctIsoPoints(pts);
  ASSERT_EQ(distinct.size(), 3u);
  EXPECT_EQ(distinct[0], pts[0]);
  EXPECT_EQ(distinct[1], pts[2]);
  EXPECT_EQ(distinct[2], pts[3]);
  EXPECT_EQ(CountDistinctIsoPoints(pts, 1e-6), 2u);
  EXPECT_EQ(CountDistinctIsoPoints(std::vector<IsoDirection>{}), 0u);
}

}  // namespace
}  // namespace brdf
