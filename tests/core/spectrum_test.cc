#include "core/spectrum.h"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <numbers>

namespace brdf {
namespace {

using ::testing::HasSubstr;

const WavelengthGrid kGrid{400, 10, 4};  // 400, 410, 420, 430 nm

Spectrum S(std::vector<double> v, WavelengthGrid g = kGrid) {
  return {g, std::move(v)};
}

TEST(SpectrumTest, ReflectanceIsRatioToWhite) {
  const Result<Spectrum> r = Reflectance(S({1, 2, 3, 4}), S({2, 4, 4, 8}));
  ASSERT_TRUE(r.ok()) << r.status().ToString();
  EXPECT_EQ(r->grid, kGrid);
  EXPECT_THAT(r->values, ::testing::ElementsAre(0.5, 0.5, 0.75, 0.5));
}

TEST(SpectrumTest, ReflectanceSubtractsDark) {
  // (3 − 1)/(5 − 1) = 0.5, (2 − 1)/(9 − 1) = 0.125, (1 − 1)/(3 − 1) = 0, (0.5 − 1)/(2 − 1) = −0.5
  const Result<Spectrum> r = Reflectance(S({3, 2, 1, 0.5}), S({5, 9, 3, 2}), S({1, 1, 1, 1}));
  ASSERT_TRUE(r.ok()) << r.status().ToString();
  EXPECT_THAT(r->values, ::testing::ElementsAre(0.5, 0.125, 0.0, -0.5));
}

TEST(SpectrumTest, ReflectanceNamesTheDarkBand) {
  Result<Spectrum> r = Reflectance(S({1, 1, 1, 1}), S({2, 2, 0, 2}));
  ASSERT_FALSE(r.ok());
  EXPECT_EQ(r.status().code(), StatusCode::kInvalidArgument);
  EXPECT_THAT(r.status().message(), HasSubstr("420 nm (band 2)"));
  r = Reflectance(S({1, 1, 1, 1}), S({2, 2, 2, 2}), S({0, 0, 0, 2.5}));
  ASSERT_FALSE(r.ok());
  EXPECT_THAT(r.status().message(), HasSubstr("430 nm (band 3)"));
}

TEST(SpectrumTest, ReflectanceRejectsMismatchedOrBrokenSpectra) {
  Result<Spectrum> r = Reflectance(S({1, 1, 1, 1}), S({1, 1, 1, 1}, {402, 10, 4}));
  ASSERT_FALSE(r.ok());
  EXPECT_THAT(r.status().message(), HasSubstr("white reference"));
  r = Reflectance(S({1, 1, 1}), S({1, 1, 1, 1}));
  ASSERT_FALSE(r.ok());
  EXPECT_THAT(r.status().message(), HasSubstr("sample reading has 3 values"));
  r = Reflectance(S({1, 1, 1, 1}), S({1, 1, 1, 1}),
                  S({0, std::numeric_limits<double>::quiet_NaN(), 0, 0}));
  ASSERT_FALSE(r.ok());
  EXPECT_THAT(r.status().message(), HasSubstr("dark reading is not finite at 410 nm"));
}

TEST(SpectrumTest, BrdfFromReflectanceAtNormalReference) {
  // f = R · 0.99 / π · cos 0 / cos 60 = R · 0.99 · 2 / π.
  const Result<Spectrum> f = BrdfFromReflectance(S({0.5, 1, 0, 0.25}), 0.99, 0, 60);
  ASSERT_TRUE(f.ok()) << f.status().ToString();
  const double k = 0.99 * 2 / std::numbers::pi;
  EXPECT_NEAR(f->values[0], 0.5 * k, 1e-12);
  EXPECT_NEAR(f->values[1], 1.0 * k, 1e-12);
  EXPECT_EQ(f->values[2], 0.0);
  EXPECT_NEAR(f->values[3], 0.25 * k, 1e-12);
}

TEST(SpectrumTest, BrdfWithSpectralWhiteAndTiltedReference) {
  // f = R · ρw / π · cos 60 / cos 0 = R · ρw / (2π).
  const Result<Spectrum> f =
      BrdfFromReflectance(S({1, 1, 2, 2}), S({0.98, 0.99, 0.99, 0.97}), 60, 0);
  ASSERT_TRUE(f.ok()) << f.status().ToString();
  EXPECT_NEAR(f->values[0], 0.98 / (2 * std::numbers::pi), 1e-12);
  EXPECT_NEAR(f->values[2], 2 * 0.99 / (2 * std::numbers::pi), 1e-12);
  EXPECT_NEAR(f->values[3], 2 * 0.97 / (2 * std::numbers::pi), 1e-12);
}

TEST(SpectrumTest, LambertianWhiteSeenAsItselfHasBrdfRhoOverPi) {
  // A sample identical to the standard at the reference pose gives R = 1, f = ρw/π.
  const Result<Spectrum> f = BrdfFromReflectance(S({1, 1, 1, 1}), kWhiteStandardReflectance, 0, 0);
  ASSERT_TRUE(f.ok());
  for (double v : f->values) EXPECT_NEAR(v, 0.99 / std::numbers::pi, 1e-15);
}

TEST(SpectrumTest, ReflectanceFromBrdfInvertsBrdfFromReflectance) {
  const Spectrum r = S({0.1, 0.4, 0.7, 1.3});
  const Result<Spectrum> f = BrdfFromReflectance(r, 0.97, 10, 55);
  ASSERT_TRUE(f.ok());
  const Result<Spectrum> back = ReflectanceFromBrdf(*f, 0.97, 10, 55);
  ASSERT_TRUE(back.ok());
  for (std::size_t k = 0; k < r.values.size(); ++k)
    EXPECT_NEAR(back->values[k], r.values[k], 1e-12);
}

TEST(SpectrumTest, BrdfRejectsGrazingAndBadWhite) {
  Result<Spectrum> f = BrdfFromReflectance(S({1, 1, 1, 1}), 0.99, 0, 90);
  ASSERT_FALSE(f.ok());
  EXPECT_EQ(f.status().code(), StatusCode::kInvalidArgument);
  EXPECT_THAT(f.status().message(), HasSubstr("theta_i (sample incidence)"));
  f = BrdfFromReflectance(S({1, 1, 1, 1}), 0.99, std::numeric_limits<double>::quiet_NaN(), 10);
  ASSERT_FALSE(f.ok());
  EXPECT_THAT(f.status().message(), HasSubstr("theta_i_ref"));
  f = BrdfFromReflectance(S({1, 1, 1, 1}), 0.0, 0, 10);
  ASSERT_FALSE(f.ok());
  EXPECT_THAT(f.status().message(), HasSubstr("white standard reflectance"));
  f = BrdfFromReflectance(S({1, 1, 1, 1}), S({0.9, -0.1, 0.9, 0.9}), 0, 10);
  ASSERT_FALSE(f.ok());
  EXPECT_THAT(f.status().message(), HasSubstr("410 nm (band 1)"));
  f = BrdfFromReflectance(S({1, 1, 1, 1}), S({0.9, 0.9, 0.9}, {400, 10, 3}), 0, 10);
  ASSERT_FALSE(f.ok());
}

TEST(SpectrumTest, ResampleIsLinear) {
  const Spectrum s = S({0, 10, 30, 60});
  const Result<Spectrum> r = Resample(s, {405, 5, 5});  // 405 … 425 nm
  ASSERT_TRUE(r.ok()) << r.status().ToString();
  EXPECT_THAT(r->values, ::testing::ElementsAre(5.0, 10.0, 20.0, 30.0, 45.0));
  // Same grid: unchanged; the last band is reachable.
  const Result<Spectrum> same = Resample(s, kGrid);
  ASSERT_TRUE(same.ok());
  EXPECT_EQ(same->values, s.values);
}

TEST(SpectrumTest, ResampleDoesNotExtrapolate) {
  const Result<Spectrum> r = Resample(S({0, 10, 30, 60}), {380, 4, 101});
  ASSERT_FALSE(r.ok());
  EXPECT_EQ(r.status().code(), StatusCode::kInvalidArgument);
  EXPECT_THAT(r.status().message(), HasSubstr("380 nm"));
  EXPECT_FALSE(Resample(S({0, 1, 2, 3}), {400, 0, 3}).ok());
}

}  // namespace
}  // namespace brdf
