// Each lobe of core/material against values worked out by hand from its formula
// (docs/materials.md), its symmetries (reciprocity; an anisotropic lobe turned by 90° is the
// lobe with its roughnesses swapped), and its energy (directional albedo).
#include <gtest/gtest.h>

#include <cmath>
#include <memory>
#include <numbers>
#include <vector>

#include "core/material/diffuse_lobes.h"
#include "core/material/directional_albedo.h"
#include "core/material/fresnel.h"
#include "core/material/glossy_lobes.h"
#include "core/material/material.h"
#include "core/material/microfacet.h"

namespace brdf::material {
namespace {

constexpr double kPi = std::numbers::pi;

double Rad(double deg) {
  return deg * kPi / 180;
}

Material One(std::shared_ptr<const Lobe> lobe) {
  return Material("test", {std::move(lobe)});
}

SpectralValue C(double v) {
  return SpectralValue::Constant(v);
}

// Pairs of directions above the surface, spread over the hemisphere (θ up to 85°).
std::vector<Directions> SomeDirections() {
  std::vector<Directions> out;
  for (double ti : {0.0, 10.0, 35.0, 60.0, 85.0}) {
    for (double to : {0.0, 20.0, 45.0, 70.0, 85.0}) {
      for (double phi : {-150.0, -40.0, 0.0, 90.0, 170.0}) out.push_back({ti, 15, to, 15 + phi});
    }
  }
  return out;
}

void ExpectReciprocal(const Material& m) {
  for (const Directions& d : SomeDirections()) {
    const Directions swapped{d.theta_o, d.phi_o, d.theta_i, d.phi_i};
    for (double nm : {400.0, 550.0, 700.0}) {
      const double f = m.Evaluate(d, nm), g = m.Evaluate(swapped, nm);
      EXPECT_NEAR(f, g, 1e-12 * std::max(1.0, std::abs(f)))
          << d.theta_i << " " << d.phi_i << " " << d.theta_o << " " << d.phi_o;
    }
  }
}

TEST(LambertLobeTest, IsAlbedoOverPiEverywhereAbove) {
  const Material m =
      One(std::make_shared<LambertLobe>(SpectralValue::Table({{400, 0.2}, {700, 0.8}})));
  EXPECT_DOUBLE_EQ(m.Evaluate({30, 0, 60, 120}, 550), 0.5 / kPi);
  EXPECT_DOUBLE_EQ(m.Evaluate({0, 0, 89, 0}, 400), 0.2 / kPi);
  EXPECT_EQ(m.Evaluate({30, 0, 91, 0}, 550), 0.0) << "below the surface";
  // The albedo of a Lambertian surface is ρ at every incidence.
  const WavelengthGrid grid{550, 1, 1};
  for (double ti : {0.0, 45.0, 80.0}) {
    EXPECT_NEAR(DirectionalAlbedo(m, ti, 0, grid, 1.0)[0], 0.5, 2e-4) << ti;
  }
}

TEST(OrenNayarLobeTest, MatchesTheQualitativeModelByHand) {
  const double sigma = 20, s2 = Rad(sigma) * Rad(sigma);
  const double a = 1 - 0.5 * s2 / (s2 + 0.33), b = 0.45 * s2 / (s2 + 0.09);
  const Material m = One(std::make_shared<OrenNayarLobe>(C(0.6), sigma));
  // θi = 60°, θo = 30°, same azimuth: α = 60°, β = 30°, cos(φi − φo) = 1.
  EXPECT_NEAR(m.Evaluate({60, 10, 30, 10}, 500),
              0.6 / kPi * (a + b * std::sin(Rad(60)) * std::tan(Rad(30))), 1e-12);
  // Azimuths 60° apart: the B term is halved.
  EXPECT_NEAR(m.Evaluate({60, 0, 30, 60}, 500),
              0.6 / kPi * (a + b * 0.5 * std::sin(Rad(60)) * std::tan(Rad(30))), 1e-12);
  // Opposite sides (cos < 0): A alone, less than Lambert.
  EXPECT_NEAR(m.Evaluate({60, 0, 30, 180}, 500), 0.6 / kPi * a, 1e-12);
  // σ = 0 is Lambert.
  EXPECT_NEAR(One(std::make_shared<OrenNayarLobe>(C(0.6), 0)).Evaluate({60, 0, 30, 0}, 500),
              0.6 / kPi, 1e-15);
  ExpectReciprocal(m);
}

TEST(OrenNayarLobeTest, RougherSurfacesBackscatterAndStayBelowOne) {
  const Material m = One(std::make_shared<OrenNayarLobe>(C(1.0), 40));
  // Back towards a grazing lamp a rough matte surface is brighter than a Lambertian one.
  EXPECT_GT(m.Evaluate({75, 0, 75, 0}, 500), 1 / kPi);
  const WavelengthGrid grid{550, 1, 1};
  for (double ti : {0.0, 30.0, 60.0, 85.0}) {
    const double a = DirectionalAlbedo(m, ti, 0, grid, 0.5)[0];
    EXPECT_LE(a, 1.0) << ti;
    EXPECT_GT(a, 0.7) << ti;
  }
}

TEST(FresnelTest, SchlickAndConductorLimits) {
  const Fresnel schlick = Fresnel::Schlick(C(0.04));
  EXPECT_DOUBLE_EQ(schlick.Reflectance(1.0, 500), 0.04);
  EXPECT_DOUBLE_EQ(schlick.Reflectance(0.0, 500), 1.0);
  EXPECT_NEAR(schlick.Reflectance(0.5, 500), 0.04 + 0.96 / 32, 1e-15);
  EXPECT_EQ(Fresnel().Reflectance(0.3, 500), 1.0);
  // Normal incidence: ((n − 1)² + k²) / ((n + 1)² + k²); grazing: 1.
  for (auto [n, k] : {std::pair{0.2, 3.0}, {1.5, 0.0}, {1.3, 7.5}}) {
    EXPECT_NEAR(ConductorReflectance(1.0, n, k),
                ((n - 1) * (n - 1) + k * k) / ((n + 1) * (n + 1) + k * k), 1e-12);
    EXPECT_NEAR(ConductorReflectance(0.0, n, k), 1.0, 1e-12);
  }
}

// The conductor's Fresnel reflectance written the other common way (real arithmetic, e.g. in
// Born & Wolf): a² + b² = sqrt((n² − k² − sin²θ)² + 4n²k²), a² = (a² + b² + n² − k² − sin²θ)/2,
// Rs = (a² + b² − 2a cos θ + cos²θ) / (a² + b² + 2a cos θ + cos²θ),
// Rp = Rs · (a² + b² − 2a sin θ tan θ + sin²θ tan²θ) / (a² + b² + 2a sin θ tan θ + sin²θ tan²θ).
double ConductorByHand(double theta, double n, double k) {
  const double c = std::cos(theta), s = std::sin(theta), t = std::tan(theta);
  const double x = n * n - k * k - s * s;
  const double ab = std::sqrt(x * x + 4 * n * n * k * k);
  const double a = std::sqrt((ab + x) / 2);
  const double rs = (ab - 2 * a * c + c * c) / (ab + 2 * a * c + c * c);
  const double rp =
      rs * (ab - 2 * a * s * t + s * s * t * t) / (ab + 2 * a * s * t + s * s * t * t);
  return (rs + rp) / 2;
}

TEST(FresnelTest, ConductorAgreesWithTheRealForm) {
  for (double deg : {10.0, 45.0, 70.0, 85.0}) {
    for (auto [n, k] : {std::pair{0.16, 3.6}, {1.4, 1.9}, {1.5, 0.0}, {2.6, 8.5}}) {
      EXPECT_NEAR(ConductorReflectance(std::cos(Rad(deg)), n, k), ConductorByHand(Rad(deg), n, k),
                  1e-12)
          << deg << " " << n << " " << k;
    }
  }
}

TEST(MicrofacetTest, DensitiesAreNormalisedOverProjectedFacets) {
  // ∫ D(h) hz dωh = 1 for both slope distributions, isotropic and not.
  for (FacetSlopes slopes : {FacetSlopes::kGgx, FacetSlopes::kBeckmann}) {
    for (Roughness alpha : {Roughness{0.3, 0.3}, Roughness{0.1, 0.4}}) {
      double sum = 0;
      const int n = 1200;
      const double dt = kPi / 2 / n, dp = 2 * kPi / (4 * n);
      for (int a = 0; a < n; ++a) {
        const double t = (a + 0.5) * dt;
        for (int b = 0; b < 4 * n; ++b) {
          const double p = (b + 0.5) * dp;
          const Vec3 h{std::sin(t) * std::cos(p), std::sin(t) * std::sin(p), std::cos(t)};
          sum += FacetDensity(slopes, alpha, h) * h.z * std::sin(t) * dt * dp;
        }
      }
      // GGX's long tail beyond 90° of slope is not in the hemisphere's grid: within 0.5 %.
      EXPECT_NEAR(sum, 1.0, 5e-3) << static_cast<int>(slopes) << " " << alpha.x;
    }
  }
}

TEST(MicrofacetTest, SmithLambdaKnownValues) {
  const Roughness a{0.5, 0.5};
  EXPECT_EQ(SmithLambda(FacetSlopes::kGgx, a, {0, 0, 1}), 0.0);
  // tan θ = 2, α = 0.5: a = 1. GGX: (−1 + √2) / 2. Beckmann: (erf 1 − 1)/2 + e⁻¹/(2√π).
  const double s = std::sin(std::atan(2.0)), c = std::cos(std::atan(2.0));
  EXPECT_NEAR(SmithLambda(FacetSlopes::kGgx, a, {s, 0, c}), (std::sqrt(2.0) - 1) / 2, 1e-12);
  EXPECT_NEAR(SmithLambda(FacetSlopes::kBeckmann, a, {s, 0, c}), 0.0251272, 1e-6);
  // Anisotropic: only the roughness along the direction's azimuth counts.
  EXPECT_NEAR(SmithLambda(FacetSlopes::kGgx, Roughness{0.5, 0.1}, {s, 0, c}),
              (std::sqrt(2.0) - 1) / 2, 1e-12);
}

TEST(MicrofacetLobeTest, AtNormalIncidenceAndViewIsF0Over4PiAlphaSquared) {
  for (FacetSlopes slopes : {FacetSlopes::kGgx, FacetSlopes::kBeckmann}) {
    const Material m = One(std::make_shared<MicrofacetLobe>(slopes, Roughness{0.2, 0.2},
                                                            Fresnel::Schlick(C(0.05)), C(1.0)));
    // h = n: D = 1/(π α²), G2 = 1, F = F0, cos θi = cos θo = 1.
    EXPECT_NEAR(m.Evaluate({0, 0, 0, 0}, 500), 0.05 / (4 * kPi * 0.04), 1e-12);
    ExpectReciprocal(m);
  }
}

TEST(MicrofacetLobeTest, ConductorLobePeaksAtTheMirrorAndUsesNK) {
  const Material m = One(std::make_shared<MicrofacetLobe>(
      FacetSlopes::kGgx, Roughness{0.15, 0.15},
      Fresnel::Conductor(SpectralValue::Table({{400, 1.5}, {700, 0.2}}),
                         SpectralValue::Table({{400, 1.9}, {700, 4.0}})),
      C(1.0)));
  const double mirror = m.Evaluate({40, 0, 40, 180}, 700);
  EXPECT_GT(mirror, m.Evaluate({40, 0, 30, 180}, 700));
  EXPECT_GT(mirror, m.Evaluate({40, 0, 40, 160}, 700));
  // At the mirror h = n and ωi·h = cos 40°: the value is F(40°) · D(n) · G2 / (4 cos² 40°).
  const double lambda = (-1 + std::sqrt(1 + 0.15 * 0.15 * std::pow(std::tan(Rad(40)), 2))) / 2;
  const double expected = ConductorReflectance(std::cos(Rad(40)), 0.2, 4.0) / (kPi * 0.15 * 0.15) /
                          (1 + 2 * lambda) / (4 * std::pow(std::cos(Rad(40)), 2));
  EXPECT_NEAR(mirror, expected, 1e-9 * expected);
  // A gold-like n, k reflects red more than blue.
  EXPECT_GT(mirror, m.Evaluate({40, 0, 40, 180}, 400));
  EXPECT_EQ(m.Evaluate({90, 0, 40, 180}, 500), 0.0) << "exactly grazing";
}

TEST(MicrofacetLobeTest, WithoutFresnelASmoothishSurfaceReflectsNearlyEverything) {
  // The white furnace: F = 1, α = 0.1: single scattering loses a little to shadowing only.
  for (FacetSlopes slopes : {FacetSlopes::kGgx, FacetSlopes::kBeckmann}) {
    const Material m =
        One(std::make_shared<MicrofacetLobe>(slopes, Roughness{0.1, 0.1}, Fresnel(), C(1.0)));
    const WavelengthGrid grid{550, 1, 1};
    // At normal incidence the exact albedo is ∫ D hz G2 dωh ≤ 1 (Beckmann's G2 is 1 to 1e-8
    // here); the midpoint rule at 0.25° overestimates a peak this narrow by 4e-5 (falling
    // fourfold per halving of the step), hence the 1e-4.
    const double normal = DirectionalAlbedo(m, 0, 0, grid, 0.25)[0];
    EXPECT_LE(normal, 1.0 + 1e-4);
    EXPECT_GT(normal, 0.97);
    const double grazing = DirectionalAlbedo(m, 80, 0, grid, 0.25)[0];
    EXPECT_LE(grazing, 1.0);
    EXPECT_LT(grazing, normal) << "shadowing grows towards grazing";
  }
}

TEST(MicrofacetLobeTest, AnisotropicGgxTurnedByNinetyDegreesSwapsItsRoughnesses) {
  const auto lobe = [](double ax, double ay) {
    return One(std::make_shared<MicrofacetLobe>(FacetSlopes::kGgx, Roughness{ax, ay},
                                                Fresnel::Schlick(C(0.9)), C(1.0)));
  };
  const Material m = lobe(0.05, 0.3), swapped = lobe(0.3, 0.05);
  EXPECT_TRUE(m.anisotropic());
  for (const Directions& d : SomeDirections()) {
    const Directions turned{d.theta_i, d.phi_i + 90, d.theta_o, d.phi_o + 90};
    EXPECT_NEAR(m.Evaluate(turned, 550), swapped.Evaluate(d, 550),
                1e-9 * std::max(1.0, swapped.Evaluate(d, 550)));
  }
  // Across the tangent (x, the narrow roughness) the highlight falls faster than along y.
  const double peak = m.Evaluate({30, 0, 30, 180}, 550);
  EXPECT_LT(m.Evaluate({30, 0, 36, 180}, 550), 0.5 * peak);
  EXPECT_GT(m.Evaluate({30, 90, 36, 270}, 550), 0.5 * peak);
  ExpectReciprocal(m);
}

TEST(BlinnPhongLobeTest, NormalisedLobeByHand) {
  const Material m = One(std::make_shared<BlinnPhongLobe>(C(0.1), 50, 50));
  // θi = 20°, θo = 40°, opposite azimuths: h is 10° from the normal.
  EXPECT_NEAR(m.Evaluate({20, 0, 40, 180}, 500),
              0.1 * 58 / (8 * kPi) * std::pow(std::cos(Rad(10)), 50), 1e-12);
  ExpectReciprocal(m);
  ExpectReciprocal(One(std::make_shared<BlinnPhongLobe>(C(0.1), 20, 200)));
}

TEST(RetroLobeTest, PeaksBackAtTheLampAndConservesEnergy) {
  const Material m = One(std::make_shared<RetroLobe>(C(0.5), 30));
  // ωo = ωi: w (e + 1) / (2π).
  EXPECT_NEAR(m.Evaluate({50, 20, 50, 20}, 500), 0.5 * 31 / (2 * kPi), 1e-12);
  EXPECT_GT(m.Evaluate({50, 20, 50, 20}, 500), 20 * m.Evaluate({50, 20, 50, 200}, 500));
  EXPECT_EQ(m.Evaluate({80, 0, 80, 180}, 500), 0.0) << "ωi·ωo < 0";
  ExpectReciprocal(m);
  // At normal incidence the albedo is w (e + 1) / (e + 2); towards grazing the lobe is cut by the
  // horizon and weighed by cos θo, so less.
  const WavelengthGrid grid{500, 1, 1};
  EXPECT_NEAR(DirectionalAlbedo(m, 0, 0, grid, 0.25)[0], 0.5 * 31 / 32, 1e-3);
  EXPECT_LT(DirectionalAlbedo(m, 70, 0, grid, 0.25)[0], 0.5 * 31 / 32);
}

TEST(SpectralValueTest, TablesInterpolateAndHoldTheirEnds) {
  const SpectralValue t = SpectralValue::Table({{400, 1.0}, {500, 2.0}, {700, 0.0}});
  EXPECT_EQ(t.At(300), 1.0);
  EXPECT_EQ(t.At(400), 1.0);
  EXPECT_DOUBLE_EQ(t.At(450), 1.5);
  EXPECT_DOUBLE_EQ(t.At(600), 1.0);
  EXPECT_EQ(t.At(800), 0.0);
  EXPECT_EQ(t.Min(), 0.0);
  EXPECT_EQ(t.Max(), 2.0);
  const SpectralValue b = SpectralValue::Bump(0.25, 0.45, 610, 90);
  EXPECT_DOUBLE_EQ(b.At(610), 0.70);
  EXPECT_NEAR(b.At(700), 0.25 + 0.45 * std::exp(-1.0), 1e-15);
  EXPECT_DOUBLE_EQ(b.Max(), 0.70);
  EXPECT_DOUBLE_EQ(b.Min(), 0.25);
  EXPECT_EQ(SpectralValue::Constant(0.3).At(123), 0.3);
}

TEST(MaterialTest, IsTheSumOfItsLobesAndZeroBelowTheSurface) {
  const auto lambert = std::make_shared<LambertLobe>(C(0.3));
  const auto retro = std::make_shared<RetroLobe>(C(0.2), 10);
  const Material both("both", {lambert, retro});
  const Directions d{30, 0, 40, 20};
  EXPECT_NEAR(both.Evaluate(d, 500), One(lambert).Evaluate(d, 500) + One(retro).Evaluate(d, 500),
              1e-15);
  EXPECT_EQ(both.Evaluate({30, 0, 95, 0}, 500), 0.0);
  EXPECT_EQ(both.Evaluate({std::nan(""), 0, 40, 0}, 500), 0.0);
  EXPECT_EQ(both.Evaluate(d, std::nan("")), 0.0);
  const std::vector<double> s = both.EvaluateSpectrum(d, WavelengthGrid::Pr650());
  ASSERT_EQ(s.size(), 101u);
  EXPECT_EQ(s[30], both.Evaluate(d, 500));
  EXPECT_FALSE(both.anisotropic());
}

}  // namespace
}  // namespace brdf::material
