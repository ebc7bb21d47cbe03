// RGL .bsdf: the tensor_file container reads back field by field; our reader (which evaluates as
// Mitsuba 3 and pbrt-v4 do) gives back the session's interpolant at random directions over the
// measured hemisphere (median relative difference < 2 %, 95th percentile < 10 %); the microfacet
// distribution from retro-reflection is normalised; the RGB variant agrees with the spectral one
// through the D65 sRGB weights.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <numbers>
#include <random>
#include <sstream>

#include "core/export/rgl/reader.h"
#include "core/export/rgl/warp.h"
#include "core/export/rgl/writer.h"
#include "core/export/synthetic_session.h"
#include "core/geometry.h"
#include "export_test_util.h"

namespace brdf::exports {
namespace {

constexpr double kPi = std::numbers::pi;

struct Fixture {
  DerivedSamples derived;
  std::unique_ptr<interp::Interpolator> octant, nearest;
  RetroProfile retro;
  double theta_max = 0;
};

const Fixture& Paint() {
  static const Fixture* f = [] {
    auto* x = new Fixture;
    Result<Session> session = SyntheticSession(AnalyticBrdf::PaintLike());
    EXPECT_TRUE(session.ok());
    Result<DerivedSamples> d = DeriveSamples(*session, Quantity::kBrdf);
    EXPECT_TRUE(d.ok());
    x->derived = std::move(*d);
    auto set = ToSampleSet(x->derived);
    interp::Options options;
    options.reciprocity = true;
    options.mirror_phi = true;
    x->octant = std::move(interp::MakeInterpolator(interp::Method::kOctant, *set, options)).value();
    x->nearest =
        std::move(interp::MakeInterpolator(interp::Method::kNearest, *set, options)).value();
    Result<RetroProfile> r = RetroReflectionFromSamples(x->derived);
    EXPECT_TRUE(r.ok()) << r.status().ToString();
    x->retro = *r;
    for (const DerivedSample& s : x->derived.samples) {
      x->theta_max = std::max({x->theta_max, s.iso.theta_i, s.iso.theta_o});
    }
    return x;
  }();
  return *f;
}

std::string Written(const RglExport& e) {
  std::ostringstream out;
  EXPECT_TRUE(WriteRgl(e.fields, out).ok());
  return out.str();
}

Result<RglExport> Build(const Fixture& f, RglOptions o) {
  o.theta_i_max_deg = std::min(f.theta_max, 89.0);
  return BuildRgl(InterpolatorSource(*f.octant), InterpolatorSource(*f.nearest), f.derived.grid,
                  f.retro, o, {0, {}}, CallContext::WithTimeout(std::chrono::hours(1)));
}

TEST(RglWarp, InvertUndoesSampleAndEvalIsTheDensity) {
  std::vector<float> data(5 * 4);
  for (std::size_t i = 0; i < data.size(); ++i) data[i] = 0.5f + static_cast<float>(i % 7);
  const Warp2D w(5, 4, data.data(), {}, true, true);
  std::mt19937 rng(3);
  std::uniform_real_distribution<float> u(0.01f, 0.99f);
  for (int t = 0; t < 200; ++t) {
    const float x = u(rng), y = u(rng);
    const WarpPoint s = w.Sample(x, y, nullptr);
    const WarpPoint back = w.Invert(s.x, s.y, nullptr);
    EXPECT_NEAR(back.x, x, 1e-4);
    EXPECT_NEAR(back.y, y, 1e-4);
    EXPECT_NEAR(s.pdf, w.Eval(s.x, s.y, nullptr), 1e-3 * s.pdf);
  }
}

TEST(RglExport, RetroReflectionReadingsGiveTheProfile) {
  const Fixture& f = Paint();
  // The paper's loops include δ = 0 (8 α × every β): retro-reflection from 0° to 70°.
  EXPECT_GE(f.retro.theta_deg.size(), 8u);
  EXPECT_NEAR(f.retro.theta_deg.front(), 0, 1e-6);
  EXPECT_GT(f.retro.theta_deg.back(), 70);
  DerivedSamples none = f.derived;
  std::erase_if(none.samples,
                [](const DerivedSample& s) { return s.iso.theta_i == s.iso.theta_o; });
  EXPECT_EQ(RetroReflectionFromSamples(none).status().code(), StatusCode::kFailedPrecondition);
}

TEST(RglExport, ContainerHoldsTheFieldsTheReadersRequire) {
  const Fixture& f = Paint();
  RglOptions o;
  o.theta_i_count = 6;
  o.sample_res = 8;
  o.description = "test";
  Result<RglExport> e = Build(f, o);
  ASSERT_TRUE(e.ok()) << e.status().ToString();
  const std::string bytes = Written(*e);
  ASSERT_EQ(bytes.substr(0, 12), std::string("tensor_file\0", 12));
  EXPECT_EQ(bytes[12], 1);
  EXPECT_EQ(bytes[13], 0);
  Result<std::map<std::string, RglTensor>> t = ParseTensorFile(bytes);
  ASSERT_TRUE(t.ok()) << t.status().ToString();
  for (const char* name : {"description", "jacobian", "theta_i", "phi_i", "ndf", "sigma", "vndf",
                           "luminance", "wavelengths", "spectra"}) {
    EXPECT_EQ(t->count(name), 1u) << name;
  }
  EXPECT_EQ(t->at("spectra").shape, (std::vector<std::uint64_t>{1, 6, 101, 8, 8}));
  EXPECT_EQ(t->at("jacobian").u8, std::vector<std::uint8_t>{1});
  EXPECT_EQ(std::string(t->at("description").u8.begin(), t->at("description").u8.end()), "test");
  EXPECT_FLOAT_EQ(t->at("wavelengths").f32.front(), 380);
  EXPECT_FLOAT_EQ(t->at("theta_i").f32.back(),
                  static_cast<float>(std::min(f.theta_max, 89.0) * kPi / 180));
  // D is normalised: ∫ D cos θm dωm = 1 (in u_θ: dω = 2π · π u sin θm du for isotropic D).
  const std::vector<float>& ndf = t->at("ndf").f32;
  const std::size_t n = t->at("ndf").shape[1];
  double total = 0;
  for (int i = 0; i < 20000; ++i) {
    const double u = (i + 0.5) / 20000, tm = u * u * kPi / 2;
    const double p = u * static_cast<double>(n - 1);
    const std::size_t k = std::min(static_cast<std::size_t>(p), n - 2);
    const double d = ndf[k] + (p - static_cast<double>(k)) * (ndf[k + 1] - ndf[k]);
    total += d * std::cos(tm) * 2 * kPi * kPi * u * std::sin(tm) / 20000;
  }
  EXPECT_NEAR(total, 1, 0.01);
  // Every file offset is 8-byte aligned; a cut file is refused with a reason.
  EXPECT_FALSE(RglMaterial::Parse(bytes.substr(0, bytes.size() - 4)).ok());
  EXPECT_EQ(e->report.cells, 6u * 64u);
  EXPECT_EQ(e->report.interpolated + e->report.fallback + e->report.below_horizon +
                e->report.unfilled_total(),
            e->report.cells);
}

TEST(RglExport, ReaderGivesBackTheInterpolantOverTheMeasuredHemisphere) {
  const Fixture& f = Paint();
  RglOptions o;
  Result<RglExport> e = Build(f, o);
  ASSERT_TRUE(e.ok()) << e.status().ToString();
  std::cout << "RGL: " << e->report.Summary() << "\n";
  const std::string bytes = Written(*e);
  std::cout << "RGL file: " << bytes.size() << " bytes\n";
  Result<RglMaterial> m = RglMaterial::Parse(bytes);
  ASSERT_TRUE(m.ok()) << m.status().ToString();
  std::mt19937 rng(11);
  std::uniform_real_distribution<double> u(0, 1);
  std::vector<double> rel;
  const std::size_t band550 = 43;  // 380 + 4 · 42.5: 552 nm
  std::vector<double> spectrum(f.derived.grid.count);
  while (rel.size() < 2000) {
    // Uniform over the measured part of the hemisphere (θ ≤ the largest measured).
    const double cmin = std::cos(f.theta_max * kPi / 180);
    const double ti = std::acos(cmin + (1 - cmin) * u(rng)) * 180 / kPi;
    const double to = std::acos(cmin + (1 - cmin) * u(rng)) * 180 / kPi;
    const double phi = 180 * u(rng);
    const IsoDirection iso{ti, to, phi};
    if (f.octant->SpectrumAt(std::vector<double>{ti, to, phi}, spectrum) !=
        interp::InterpStatus::kOk) {
      continue;
    }
    const std::vector<double> file = m->Brdf(CanonicalDirections(iso));
    for (std::size_t b : {std::size_t{10}, band550, std::size_t{80}}) {
      rel.push_back(std::abs(file[b] - spectrum[b]) / spectrum[b]);
    }
  }
  std::sort(rel.begin(), rel.end());
  const double median = rel[rel.size() / 2], p95 = rel[rel.size() * 95 / 100];
  std::cout << "RGL vs interpolant: median " << 100 * median << " %, 95th percentile " << 100 * p95
            << " %\n";
  EXPECT_LT(median, 0.02);
  EXPECT_LT(p95, 0.10);
}

TEST(RglExport, RgbFileIsTheSpectralFileThroughTheD65Weights) {
  const Fixture& f = Paint();
  RglOptions o;
  o.theta_i_count = 8;
  o.sample_res = 16;
  Result<RglExport> spectral = Build(f, o);
  o.rgb = testing::D65Weights(f.derived.grid);
  Result<RglExport> rgb = Build(f, o);
  ASSERT_TRUE(spectral.ok() && rgb.ok());
  Result<std::map<std::string, RglTensor>> t = ParseTensorFile(Written(*rgb));
  ASSERT_TRUE(t.ok());
  EXPECT_EQ(t->count("spectra") + t->count("wavelengths"), 0u);
  EXPECT_EQ(t->at("rgb").shape, (std::vector<std::uint64_t>{1, 8, 3, 16, 16}));
  Result<RglMaterial> ms = RglMaterial::Parse(Written(*spectral));
  Result<RglMaterial> mr = RglMaterial::Parse(Written(*rgb));
  ASSERT_TRUE(ms.ok() && mr.ok());
  EXPECT_TRUE(mr->rgb());
  std::mt19937 rng(2);
  std::uniform_real_distribution<double> u(0, 1);
  for (int q = 0; q < 200; ++q) {
    const Directions d{70 * u(rng), 360 * u(rng), 70 * u(rng), 360 * u(rng)};
    const std::vector<double> s = ms->Brdf(d);
    const Rgb expected = o.rgb->Apply(s);
    const std::vector<double> c = mr->Brdf(d);
    ASSERT_EQ(c.size(), 3u);
    const double e[3] = {expected.r, expected.g, expected.b};
    for (int k = 0; k < 3; ++k) EXPECT_NEAR(c[k], std::max(0.0, e[k]), 1e-4 + 1e-4 * e[k]) << q;
  }
}

}  // namespace
}  // namespace brdf::exports
