#include "core/appearance.h"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <cmath>
#include <fstream>
#include <numbers>
#include <sstream>
#include <string>

namespace brdf {
namespace {

using ::testing::HasSubstr;

// colord-data is a declared dependency (deploy/install-deps.sh); the test reads its files.
SpectralTable ColordTable(const std::string& relative) {
  const std::string path = "/usr/share/colord/" + relative;
  std::ifstream in(path);
  EXPECT_TRUE(in.good()) << "cannot read " << path << "; install the colord-data package";
  std::ostringstream s;
  s << in.rdbuf();
  Result<SpectralTable> t = ParseSpectralTable(s.str());
  EXPECT_TRUE(t.ok()) << relative << ": " << t.status().ToString();
  return t.ok() ? std::move(t).value() : SpectralTable{};
}

ColorMatchingFunctions Cie1931() {
  Result<ColorMatchingFunctions> cmf =
      ColorMatchingFunctionsFromTable(ColordTable("cmf/CIE1931-2deg-XYZ.cmf"));
  EXPECT_TRUE(cmf.ok());
  return cmf.ok() ? std::move(cmf).value() : ColorMatchingFunctions{};
}

Spectrum D65() {
  Result<Spectrum> s = ColordTable("illuminant/CIE-D65.sp").SetAsSpectrum(0);
  EXPECT_TRUE(s.ok());
  return s.ok() ? std::move(s).value() : Spectrum{};
}

const WavelengthGrid kGrid = WavelengthGrid::Pr650();

BrdfLookup Lambertian(double rho) {
  return [rho](const IsoDirection&, std::span<double> out) {
    std::fill(out.begin(), out.end(), rho / std::numbers::pi);
    return true;
  };
}

// Blinn-Phong with a sharp lobe, in the isotropic convention (φ = 180° on the mirror side).
BrdfLookup Glossy() {
  return [](const IsoDirection& d, std::span<double> out) {
    constexpr double r = std::numbers::pi / 180;
    const double wi[3] = {std::sin(d.theta_i * r), 0, std::cos(d.theta_i * r)};
    const double wo[3] = {std::sin(d.theta_o * r) * std::cos(d.phi * r),
                          std::sin(d.theta_o * r) * std::sin(d.phi * r), std::cos(d.theta_o * r)};
    const double h[3] = {wi[0] + wo[0], wi[1] + wo[1], wi[2] + wo[2]};
    const double hz = h[2] / std::sqrt(h[0] * h[0] + h[1] * h[1] + h[2] * h[2]);
    std::fill(out.begin(), out.end(), 0.05 / std::numbers::pi + 1.0 * std::pow(hz, 400));
    return true;
  };
}

const std::uint8_t* Pixel(const LitSphere& s, int row, int col) {
  return &s.rgba[(static_cast<std::size_t>(row) * s.size + col) * 4];
}

// The pixel where a unit direction (x, y, z ≥ 0) is the normal.
std::pair<int, int> PixelOf(const LitSphere& s, double x, double y) {
  return {static_cast<int>((1 - y) / 2 * s.size), static_cast<int>((x + 1) / 2 * s.size)};
}

// The centre of the opaque pixels of largest r + g + b (a clipped highlight is a patch).
std::pair<int, int> Brightest(const LitSphere& s) {
  int best = -1;
  for (std::size_t i = 0; i < s.rgba.size(); i += 4) {
    if (s.rgba[i + 3] == 255) best = std::max(best, s.rgba[i] + s.rgba[i + 1] + s.rgba[i + 2]);
  }
  double rows = 0, cols = 0, count = 0;
  for (int row = 0; row < s.size; ++row) {
    for (int col = 0; col < s.size; ++col) {
      const std::uint8_t* p = Pixel(s, row, col);
      if (p[3] == 255 && p[0] + p[1] + p[2] == best) {
        rows += row;
        cols += col;
        ++count;
      }
    }
  }
  return {static_cast<int>(std::lround(rows / count)), static_cast<int>(std::lround(cols / count))};
}

TEST(AppearanceTest, GreyLambertianIsNeutralWithYEqualToRho) {
  const Result<SampleColour> c = ComputeSampleColour(Lambertian(0.4), kGrid, D65(), Cie1931());
  ASSERT_TRUE(c.ok()) << c.status().ToString();
  EXPECT_NEAR(c->xyz.Y, 0.4, 1e-9);
  const Result<Xyz> white = WhitePoint(D65(), Cie1931(), kGrid);
  ASSERT_TRUE(white.ok());
  const Chromaticity w = *ToChromaticity(*white);
  EXPECT_NEAR(c->xy.x, w.x, 1e-9);
  EXPECT_NEAR(c->xy.y, w.y, 1e-9);
  EXPECT_EQ(c->srgb8[0], c->srgb8[1]);
  EXPECT_EQ(c->srgb8[1], c->srgb8[2]);
  // sRGB of linear 0.4: 0.665 → 170.
  EXPECT_NEAR(c->srgb8[0], 170, 1);
  EXPECT_EQ(c->hex, HexColour(c->srgb8));
  EXPECT_EQ(c->hex.size(), 7U);
  for (double v : c->reflectance.values) EXPECT_NEAR(v, 0.4, 1e-12);
}

TEST(AppearanceTest, SpectralColourIsColorimetrysAt45x0) {
  Spectrum red{kGrid, std::vector<double>(kGrid.count)};
  for (std::size_t k = 0; k < kGrid.count; ++k) red.values[k] = kGrid.at(k) > 600 ? 0.7 : 0.06;
  IsoDirection asked{-1, -1, -1};
  const BrdfLookup brdf = [&](const IsoDirection& at, std::span<double> out) {
    asked = at;
    for (std::size_t k = 0; k < out.size(); ++k) out[k] = red.values[k] / std::numbers::pi;
    return true;
  };
  const Result<SampleColour> c = ComputeSampleColour(brdf, kGrid, D65(), Cie1931());
  ASSERT_TRUE(c.ok()) << c.status().ToString();
  EXPECT_EQ(asked, (IsoDirection{45, 0, 0}));
  const Result<Xyz> want = ReflectanceToXyz(red, D65(), Cie1931());
  ASSERT_TRUE(want.ok());
  EXPECT_NEAR(c->xyz.X, want->X, 1e-12);
  EXPECT_NEAR(c->xyz.Y, want->Y, 1e-12);
  EXPECT_NEAR(c->xyz.Z, want->Z, 1e-12);
  EXPECT_GT(c->srgb8[0], 2 * c->srgb8[2]);
}

TEST(AppearanceTest, IlluminantAFormulaMatchesColordsTable) {
  const Result<Spectrum> colord = ColordTable("illuminant/CIE-A.sp").SetAsSpectrum(0);
  ASSERT_TRUE(colord.ok());
  const Spectrum a = CieIlluminantA({300, 1, 531});
  const double a560 = a.values[260];
  EXPECT_NEAR(a560, 100, 1e-9);
  const double c560 = colord->values[260];
  for (std::size_t k = 0; k < a.values.size(); ++k) {
    EXPECT_NEAR(a.values[k] / a560, colord->values[k] / c560, 2e-4 * a.values[k] / a560)
        << a.grid.at(k) << " nm";
  }
  // CIE 15's white point of A (2°): x = 0.44758, y = 0.40745.
  const Result<Xyz> white = WhitePoint(a, Cie1931(), kGrid);
  ASSERT_TRUE(white.ok());
  const Chromaticity xy = *ToChromaticity(*white);
  EXPECT_NEAR(xy.x, 0.4476, 1e-3);
  EXPECT_NEAR(xy.y, 0.4074, 1e-3);
}

TEST(AppearanceTest, NoValueAt45x0IsAnError) {
  const BrdfLookup none = [](const IsoDirection&, std::span<double>) { return false; };
  const Result<SampleColour> c = ComputeSampleColour(none, kGrid, D65(), Cie1931());
  ASSERT_FALSE(c.ok());
  EXPECT_EQ(c.status().code(), StatusCode::kFailedPrecondition);
  EXPECT_THAT(c.status().message(), HasSubstr("45°:0°"));
}

TEST(AppearanceTest, SphereIsBrightestTowardTheLightAndTransparentOutside) {
  SphereOptions o;
  o.size = 96;
  const Result<LitSphere> s = RenderLitSphere(Lambertian(0.5), kGrid, D65(), Cie1931(), o);
  ASSERT_TRUE(s.ok()) << s.status().ToString();
  ASSERT_EQ(s->rgba.size(), 96U * 96U * 4U);
  EXPECT_EQ(Pixel(*s, 0, 0)[3], 0);    // a corner: outside the disc
  EXPECT_EQ(Pixel(*s, 95, 95)[3], 0);  // another
  EXPECT_EQ(Pixel(*s, 48, 48)[3], 255);
  EXPECT_NEAR(static_cast<double>(s->disc_pixels), std::numbers::pi * 48 * 48, 150);
  EXPECT_GT(s->unlit_pixels, 0U);
  EXPECT_EQ(s->missing_pixels, 0U);
  EXPECT_NEAR(s->peak_y, 0.5, 0.01);  // π · ρ/π · cos θi ≤ ρ

  // The brightest pixel's normal is the light's direction.
  const double len = std::sqrt(0.25 + 0.36 + 0.62 * 0.62);
  const auto [lr, lc] = PixelOf(*s, -0.5 / len, 0.6 / len);
  const auto [br, bc] = Brightest(*s);
  EXPECT_LE(std::abs(br - lr), 3) << "brightest at row " << br << ", light at row " << lr;
  EXPECT_LE(std::abs(bc - lc), 3) << "brightest at col " << bc << ", light at col " << lc;
  // Facing away from the light (lower right, near the rim): opaque black.
  const auto [ur, uc] = PixelOf(*s, 0.65, -0.7);
  const std::uint8_t* unlit = Pixel(*s, ur, uc);
  EXPECT_EQ(unlit[3], 255);
  EXPECT_EQ(unlit[0] + unlit[1] + unlit[2], 0);
}

TEST(AppearanceTest, WhiteLambertianLitHeadOnIsWhite) {
  SphereOptions o;
  o.size = 64;
  o.light = {0, 0, 2};
  const Result<LitSphere> s = RenderLitSphere(Lambertian(1.0), kGrid, D65(), Cie1931(), o);
  ASSERT_TRUE(s.ok());
  EXPECT_EQ(s->unlit_pixels, 0U);
  const std::uint8_t* centre = Pixel(*s, 32, 32);
  for (int k = 0; k < 3; ++k) EXPECT_GE(centre[k], 253) << k;
  EXPECT_NEAR(s->peak_y, 1.0, 1e-3);
}

TEST(AppearanceTest, HighlightSitsAtTheHalfVector) {
  SphereOptions o;
  o.size = 128;
  const Result<LitSphere> s = RenderLitSphere(Glossy(), kGrid, D65(), Cie1931(), o);
  ASSERT_TRUE(s.ok());
  // Normal halfway between the light and the view (0, 0, 1).
  const double len = std::sqrt(0.25 + 0.36 + 0.62 * 0.62);
  double h[3] = {-0.5 / len, 0.6 / len, 0.62 / len + 1};
  const double hl = std::sqrt(h[0] * h[0] + h[1] * h[1] + h[2] * h[2]);
  const auto [hr, hc] = PixelOf(*s, h[0] / hl, h[1] / hl);
  const auto [br, bc] = Brightest(*s);
  EXPECT_LE(std::abs(br - hr), 2) << "highlight at row " << br << ", half vector at " << hr;
  EXPECT_LE(std::abs(bc - hc), 2) << "highlight at col " << bc << ", half vector at " << hc;
  EXPECT_GT(s->peak_y, 1.0);  // the highlight clips
}

TEST(AppearanceTest, IlluminantAIsRedderThanD65) {
  SphereOptions o;
  o.size = 64;
  const ColorMatchingFunctions cmf = Cie1931();
  const Result<LitSphere> d65 = RenderLitSphere(Lambertian(0.5), kGrid, D65(), cmf, o);
  const Result<LitSphere> a =
      RenderLitSphere(Lambertian(0.5), kGrid, CieIlluminantA(kGrid), cmf, o);
  ASSERT_TRUE(d65.ok());
  ASSERT_TRUE(a.ok());
  auto ratio = [](const LitSphere& s) {
    double r = 0, b = 0;
    for (std::size_t i = 0; i < s.rgba.size(); i += 4) {
      r += s.rgba[i];
      b += s.rgba[i + 2];
    }
    return r / b;
  };
  EXPECT_NEAR(ratio(*d65), 1.0, 0.02);
  EXPECT_GT(ratio(*a), 1.3 * ratio(*d65));
}

TEST(AppearanceTest, RefusesBadSizeAndLight) {
  SphereOptions o;
  o.size = kMaxSphereSize + 1;
  Result<LitSphere> s = RenderLitSphere(Lambertian(0.5), kGrid, D65(), Cie1931(), o);
  ASSERT_FALSE(s.ok());
  EXPECT_THAT(s.status().message(), HasSubstr("give 1 to 512"));
  o.size = 0;
  EXPECT_FALSE(RenderLitSphere(Lambertian(0.5), kGrid, D65(), Cie1931(), o).ok());
  o.size = 8;
  o.light = {0, 0, 0};
  s = RenderLitSphere(Lambertian(0.5), kGrid, D65(), Cie1931(), o);
  ASSERT_FALSE(s.ok());
  EXPECT_THAT(s.status().message(), HasSubstr("light"));
  o.light = {0, 0, 1};
  s = RenderLitSphere(Lambertian(0.5), WavelengthGrid{300, 5, 200}, D65(), Cie1931(), o);
  EXPECT_FALSE(s.ok());  // the CMFs stop at 780 nm
}

}  // namespace
}  // namespace brdf
