#include "core/analytic_brdf.h"

#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <numbers>
#include <vector>

namespace brdf {
namespace {

// A deterministic spread of directions above the surface, including normal and grazing ones.
std::vector<Directions> SomeDirections() {
  std::vector<Directions> out;
  const double thetas[] = {0, 1e-7, 10, 30, 45, 60, 75, 89, 90};
  const double phis[] = {-179, -120, -45, 0, 30, 90, 135, 180};
  for (double ti : thetas)
    for (double to : thetas)
      for (double pi : phis)
        for (double po : phis) out.push_back({ti, pi, to, po});
  return out;
}

TEST(AnalyticBrdfTest, IsReciprocal) {
  for (const AnalyticBrdf& f : {AnalyticBrdf::PaintLike(), AnalyticBrdf::Brushed()}) {
    for (const Directions& d : SomeDirections()) {
      const Directions swapped{d.theta_o, d.phi_o, d.theta_i, d.phi_i};
      EXPECT_DOUBLE_EQ(f.Evaluate(d, 550), f.Evaluate(swapped, 550))
          << d.theta_i << " " << d.phi_i << " " << d.theta_o << " " << d.phi_o;
    }
  }
}

TEST(AnalyticBrdfTest, IsNonNegativeAndFinite) {
  for (const AnalyticBrdf& f : {AnalyticBrdf::PaintLike(), AnalyticBrdf::Brushed()}) {
    for (const Directions& d : SomeDirections()) {
      for (double nm : {380.0, 550.0, 780.0}) {
        const double v = f.Evaluate(d, nm);
        EXPECT_TRUE(std::isfinite(v));
        EXPECT_GE(v, 0.0);
      }
    }
  }
  // Both grazing and exactly opposite: the half vector vanishes.
  const double v = AnalyticBrdf::PaintLike().Evaluate({90, 0, 90, 180}, 550);
  EXPECT_TRUE(std::isfinite(v));
  EXPECT_GT(v, 0.0);
}

TEST(AnalyticBrdfTest, PaintLikeIsIsotropic) {
  const AnalyticBrdf f = AnalyticBrdf::PaintLike();
  EXPECT_FALSE(f.anisotropic());
  for (const Directions& d : SomeDirections()) {
    for (double shift : {17.0, 90.0, -133.0}) {
      const Directions rotated{d.theta_i, d.phi_i + shift, d.theta_o, d.phi_o + shift};
      EXPECT_NEAR(f.Evaluate(d, 600), f.Evaluate(rotated, 600), 1e-9 * f.Evaluate(d, 600));
    }
  }
}

TEST(AnalyticBrdfTest, BrushedIsAnisotropic) {
  const AnalyticBrdf f = AnalyticBrdf::Brushed();
  EXPECT_TRUE(f.anisotropic());
  // Same off-specular geometry, in the tangent plane and in the bitangent plane: the bitangent
  // exponent is larger, so the lobe falls off faster there.
  const double along_t = f.Evaluate({30, 180, 40, 0}, 550);
  const double along_b = f.Evaluate({30, -90, 40, 90}, 550);
  EXPECT_GT(along_t, along_b);
  // At the mirror direction both reach the same peak.
  EXPECT_DOUBLE_EQ(f.Evaluate({30, 180, 30, 0}, 550), f.Evaluate({30, -90, 30, 90}, 550));
}

TEST(AnalyticBrdfTest, LambertianLimitWithoutSpecular) {
  AnalyticBrdfParams p;
  p.specular_weight = 0;
  const AnalyticBrdf f(p);
  for (double nm : {400.0, 610.0, 700.0}) {
    const double u = (nm - p.diffuse_peak_nm) / p.diffuse_width_nm;
    const double expected = (p.diffuse_base + p.diffuse_amp * std::exp(-u * u)) / std::numbers::pi;
    for (const Directions& d : SomeDirections()) EXPECT_DOUBLE_EQ(f.Evaluate(d, nm), expected);
  }
}

TEST(AnalyticBrdfTest, SpecularPeakAtMirrorDirection) {
  const AnalyticBrdf f = AnalyticBrdf::PaintLike();
  const double mirror = f.Evaluate({40, 0, 40, 180}, 550);
  EXPECT_GT(mirror, f.Evaluate({40, 0, 50, 180}, 550));
  EXPECT_GT(mirror, f.Evaluate({40, 0, 40, 160}, 550));
  EXPECT_GT(mirror, f.Evaluate({40, 0, 40, 0}, 550));
  // At the mirror direction h = n, so the lobe contributes its full height.
  const AnalyticBrdfParams& p = f.params();
  const double diffuse = AnalyticBrdf([&] {
                           AnalyticBrdfParams q = p;
                           q.specular_weight = 0;
                           return q;
                         }())
                             .Evaluate({40, 0, 40, 180}, 550);
  EXPECT_NEAR(mirror - diffuse, p.specular_weight * (p.exponent_x + 8) / (8 * std::numbers::pi),
              1e-12);
}

TEST(AnalyticBrdfTest, ZeroBelowTheSurface) {
  const AnalyticBrdf f = AnalyticBrdf::PaintLike();
  EXPECT_EQ(f.Evaluate({90.5, 0, 30, 180}, 550), 0.0);
  EXPECT_EQ(f.Evaluate({30, 0, 120, 180}, 550), 0.0);
  EXPECT_GT(f.Evaluate({90, 0, 30, 180}, 550), 0.0);
  const double nan = std::numeric_limits<double>::quiet_NaN();
  EXPECT_EQ(f.Evaluate({nan, 0, 30, 180}, 550), 0.0);
  EXPECT_EQ(f.Evaluate({30, 0, 30, 180}, nan), 0.0);
}

TEST(AnalyticBrdfTest, SpectrumMatchesPointwiseEvaluation) {
  const AnalyticBrdf f = AnalyticBrdf::Brushed();
  const WavelengthGrid grid = WavelengthGrid::Pr650();
  const Directions d{35, 20, 50, -150};
  const std::vector<double> s = f.EvaluateSpectrum(d, grid);
  ASSERT_EQ(s.size(), grid.count);
  for (std::size_t k = 0; k < grid.count; ++k) EXPECT_DOUBLE_EQ(s[k], f.Evaluate(d, grid.at(k)));
  // The diffuse base is warm: more red than blue.
  EXPECT_GT(s[grid.count - 30], s[5]);
  const std::vector<double> below = f.EvaluateSpectrum({95, 0, 10, 0}, grid);
  for (double v : below) EXPECT_EQ(v, 0.0);
}

}  // namespace
}  // namespace brdf
