// MERL .binary: the layout mirrors the reference reader (every cell's directions map back to the
// cell), the file has the reader's size and dims, a known analytic BRDF exported through it reads
// back at sample directions, missing cells hold −1 and are counted, RGB is D65 linear sRGB.
#include <gtest/gtest.h>

#include <cmath>
#include <cstring>
#include <numbers>
#include <random>
#include <sstream>

#include "core/export/merl/reader.h"
#include "core/export/merl/writer.h"
#include "core/export/synthetic_session.h"
#include "core/geometry.h"
#include "core/interp/octant/octant.h"
#include "export_test_util.h"

namespace brdf::exports {
namespace {

constexpr double kPi = std::numbers::pi;

CallContext LongContext() {
  return CallContext::WithTimeout(std::chrono::hours(1));
}

TEST(MerlLayout, EveryCellsDirectionsLookUpTheSameCell) {
  std::size_t above = 0;
  for (int i = 0; i < kMerlThetaHalfRes; ++i) {
    for (int j = 0; j < kMerlThetaDiffRes; ++j) {
      for (int k = 0; k < kMerlPhiDiffRes; ++k) {
        const MerlCellDirections c = CellDirections(i, j, k);
        const Directions& d = c.directions;
        const HalfDiff hd = StdToHalfDiff(d.theta_i * kPi / 180, d.phi_i * kPi / 180,
                                          d.theta_o * kPi / 180, d.phi_o * kPi / 180);
        ASSERT_EQ(MerlThetaHalfIndex(hd.theta_half), i) << i << " " << j << " " << k;
        ASSERT_EQ(MerlThetaDiffIndex(hd.theta_diff), j) << i << " " << j << " " << k;
        ASSERT_EQ(MerlPhiDiffIndex(hd.phi_diff), k) << i << " " << j << " " << k;
        EXPECT_EQ(c.above, d.theta_i <= 90 && d.theta_o <= 90);
        // Independently: with φh = 0, cos θi = cos θh cos θd − sin θh sin θd cos φd and
        // cos θo = cos θh cos θd + sin θh sin θd cos φd.
        const double th = (i + 0.5) * (i + 0.5) / 90 * kPi / 180, td = (j + 0.5) * kPi / 180,
                     pd = (k + 0.5) * kPi / 180;
        const double a = std::cos(th) * std::cos(td),
                     b = std::sin(th) * std::sin(td) * std::cos(pd);
        EXPECT_EQ(c.above, a - std::abs(b) >= 0) << i << " " << j << " " << k;
        above += c.above;
      }
    }
  }
  // Most of the table is above the horizon: the θh index crowds small half angles.
  EXPECT_GT(above, kMerlCells / 2);
  EXPECT_LT(above, kMerlCells);
}

TEST(MerlLayout, IndexFunctionsFollowTheReader) {
  // θh is indexed non-linearly: index i starts at θh = i² / 90 degrees.
  EXPECT_EQ(MerlThetaHalfIndex(0.0), 0);
  EXPECT_EQ(MerlThetaHalfIndex(1.0 * kPi / 180), 9);    // √(1 · 90) = 9.49
  EXPECT_EQ(MerlThetaHalfIndex(10.0 * kPi / 180), 30);  // √900
  EXPECT_EQ(MerlThetaHalfIndex(kPi / 2), 89);           // clamped
  EXPECT_EQ(MerlThetaDiffIndex(45.5 * kPi / 180), 45);
  // φd is folded by reciprocity: −30° and 150° are the same cell.
  EXPECT_EQ(MerlPhiDiffIndex(-30.0 * kPi / 180), MerlPhiDiffIndex(150.0 * kPi / 180));
  EXPECT_EQ(MerlPhiDiffIndex(150.2 * kPi / 180), 150);
  EXPECT_EQ(MerlIndex(1, 2, 3), 3u + 2u * 180u + 1u * 180u * 90u);
  // Specular reflection at 30°: θh = 0, θd = 30°.
  const HalfDiff hd = StdToHalfDiff(kPi / 6, 0, kPi / 6, kPi);
  EXPECT_NEAR(hd.theta_half, 0, 1e-12);
  EXPECT_NEAR(hd.theta_diff, kPi / 6, 1e-12);
}

TEST(SpectralRgb, WeightsAgreeWithColorimetryAndWhiteIsNeutral) {
  const WavelengthGrid grid = WavelengthGrid::Pr650();
  const testing::CieTables cie = testing::LoadCie();
  const SpectralRgbWeights w = testing::D65Weights(grid);
  std::mt19937 rng(5);
  std::uniform_real_distribution<double> u(0, 1);
  for (int t = 0; t < 5; ++t) {
    Spectrum s{grid, std::vector<double>(grid.count)};
    for (double& v : s.values) v = u(rng);
    Result<Xyz> xyz = ReflectanceToXyz(s, cie.d65, cie.cmf);
    ASSERT_TRUE(xyz.ok());
    const Rgb want = XyzToLinearSrgb(*xyz);
    const Rgb got = w.Apply(s.values);
    EXPECT_NEAR(got.r, want.r, 1e-12);
    EXPECT_NEAR(got.g, want.g, 1e-12);
    EXPECT_NEAR(got.b, want.b, 1e-12);
  }
  // A white Lambertian BRDF (1/π sr⁻¹ in every band) is neutral under D65: RGB ≈ 1/π each.
  const Rgb white = w.Apply(std::vector<double>(grid.count, 1 / kPi));
  EXPECT_NEAR(white.r * kPi, 1.0, 5e-3);
  EXPECT_NEAR(white.g * kPi, 1.0, 5e-3);
  EXPECT_NEAR(white.b * kPi, 1.0, 5e-3);
}

// The paint-like sample exported directly (no interpolation): values at the cells are exact. A
// 20 nm grid (21 bands) keeps the 1.46 million evaluations quick.
const WavelengthGrid kCoarse{380, 20, 21};

class AnalyticMerl : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    const WavelengthGrid grid = kCoarse;
    weights_ = new SpectralRgbWeights(testing::D65Weights(grid));
    Result<MerlExport> e = BuildMerlTable(AnalyticSource(AnalyticBrdf::PaintLike(), grid), grid,
                                          *weights_, RunControl{2, {}}, LongContext());
    ASSERT_TRUE(e.ok()) << e.status().ToString();
    std::ostringstream out;
    ASSERT_TRUE(WriteMerl(e->table, out).ok());
    bytes_ = new std::string(out.str());
    report_ = new MerlReport(e->report);
  }
  static void TearDownTestSuite() {
    delete weights_;
    delete bytes_;
    delete report_;
  }
  static Rgb Truth(const Directions& d) {
    return weights_->Apply(AnalyticBrdf::PaintLike().EvaluateSpectrum(d, kCoarse));
  }
  static SpectralRgbWeights* weights_;
  static std::string* bytes_;
  static MerlReport* report_;
};
SpectralRgbWeights* AnalyticMerl::weights_ = nullptr;
std::string* AnalyticMerl::bytes_ = nullptr;
MerlReport* AnalyticMerl::report_ = nullptr;

TEST_F(AnalyticMerl, FileHasTheReadersSizeAndDims) {
  ASSERT_EQ(bytes_->size(), 12u + 3u * 8u * 90u * 90u * 180u);
  std::int32_t dims[3];
  std::memcpy(dims, bytes_->data(), 12);  // little-endian host, as the reader assumes
  EXPECT_EQ(dims[0], 90);
  EXPECT_EQ(dims[1], 90);
  EXPECT_EQ(dims[2], 180);
  EXPECT_TRUE(ParseMerl(*bytes_).ok());
}

TEST_F(AnalyticMerl, ReadsBackExactlyAtCellDirections) {
  Result<MerlTable> table = ParseMerl(*bytes_);
  ASSERT_TRUE(table.ok());
  std::mt19937 rng(7);
  std::uniform_int_distribution<int> ih(0, 89), id(0, 89), ip(0, 179);
  int checked = 0;
  while (checked < 500) {
    const MerlCellDirections c = CellDirections(ih(rng), id(rng), ip(rng));
    if (!c.above) continue;
    const Rgb got = LookupMerl(*table, c.directions);
    const Rgb want = Truth(c.directions);
    EXPECT_NEAR(got.r, want.r, 1e-12 * std::abs(want.r) + 1e-15);
    EXPECT_NEAR(got.g, want.g, 1e-12 * std::abs(want.g) + 1e-15);
    EXPECT_NEAR(got.b, want.b, 1e-12 * std::abs(want.b) + 1e-15);
    ++checked;
  }
}

TEST_F(AnalyticMerl, ReadsBackNearTheTruthAtArbitraryDirections) {
  // Anywhere in a cell the lookup returns the cell's value: within half a cell of the query. The
  // diffuse part barely changes over half a degree; the lobe (exponent 60) changes by at most a
  // few percent of its peak. Tolerance: 2 % of the value plus 3 % of the lobe's peak RGB.
  Result<MerlTable> table = ParseMerl(*bytes_);
  ASSERT_TRUE(table.ok());
  const double peak = Truth({30, 0, 30, 180}).g - Truth({30, 0, 30, 0}).g;
  std::mt19937 rng(11);
  std::uniform_real_distribution<double> th(0, 80), ph(-180, 180);
  for (int t = 0; t < 2000; ++t) {
    const Directions d{th(rng), ph(rng), th(rng), ph(rng)};
    const Rgb got = LookupMerl(*table, d);
    const Rgb want = Truth(d);
    ASSERT_GE(got.r, 0) << "a direction above the surface never lands in a missing cell here";
    EXPECT_NEAR(got.r, want.r, 0.02 * want.r + 0.03 * peak);
    EXPECT_NEAR(got.g, want.g, 0.02 * want.g + 0.03 * peak);
    EXPECT_NEAR(got.b, want.b, 0.02 * want.b + 0.03 * peak);
  }
}

TEST_F(AnalyticMerl, CellsBelowTheHorizonHoldMinusOneAndAreCounted) {
  Result<MerlTable> table = ParseMerl(*bytes_);
  ASSERT_TRUE(table.ok());
  std::size_t below = 0, minus_one = 0;
  for (int i = 0; i < 90; ++i) {
    for (int j = 0; j < 90; ++j) {
      for (int k = 0; k < 180; ++k) {
        const std::size_t ind = MerlIndex(i, j, k);
        const bool missing = table->stored[ind] == kMerlMissing;
        EXPECT_EQ(missing, table->stored[ind + 2 * kMerlCells] == kMerlMissing);
        minus_one += missing;
        below += !CellDirections(i, j, k).above;
      }
    }
  }
  EXPECT_EQ(report_->below_horizon, below);
  EXPECT_EQ(minus_one, below);
  EXPECT_EQ(report_->filled + report_->below_horizon, kMerlCells);
  EXPECT_EQ(report_->unfilled_total(), 0u);
}

TEST(MerlExport, InterpolatorSourceSortsItsBatchesWithTheOneByOneAnswers) {
  // The export's product path: a session's octant interpolator answers the table's cells in
  // batches sorted by cell (SpectraAt), and the table is the one a cell-by-cell source makes.
  const std::optional<testing::PaintGridSamples> samples = testing::PaintLikeGridSamples();
  ASSERT_TRUE(samples.has_value());
  const DerivedSamples& derived = samples->derived;
  const std::shared_ptr<const interp::SampleSet>& set = samples->set;
  auto octant = interp::OctantInterpolator::Create(set);
  ASSERT_TRUE(octant.ok());
  const interp::OctantInterpolator& in = **octant;
  const SpectrumSource one_by_one = [&in](const IsoDirection& at, std::span<double> out) {
    const double q[3] = {at.theta_i, at.theta_o, at.phi};
    return in.SpectrumAt(q, out);
  };
  const SpectralRgbWeights w = testing::D65Weights(derived.grid);
  Result<MerlExport> batched =
      BuildMerlTable(InterpolatorSource(in), derived.grid, w, RunControl{2, {}}, LongContext());
  ASSERT_TRUE(batched.ok()) << batched.status().ToString();
  const std::uint64_t sorted = in.sorted_queries();
  EXPECT_GT(sorted, kMerlCells / 4);  // every cell above the horizon, in batches of a chunk
  Result<MerlExport> single =
      BuildMerlTable(one_by_one, derived.grid, w, RunControl{2, {}}, LongContext());
  ASSERT_TRUE(single.ok());
  EXPECT_EQ(in.sorted_queries(), sorted);
  EXPECT_EQ(std::memcmp(batched->table.stored.data(), single->table.stored.data(),
                        batched->table.stored.size() * sizeof(double)),
            0);
  EXPECT_EQ(batched->report.Summary(), single->report.Summary());
  EXPECT_GT(batched->report.filled, 0u);
}

TEST(MerlExport, UnfilledCellsHoldMinusOneAndParallelEqualsSerial) {
  const WavelengthGrid grid{400, 100, 4};
  const SpectralRgbWeights w = testing::D65Weights(grid);
  // Fails where θi > 50° (outside the hull); elsewhere a smooth function of the directions.
  const SpectrumSource source = [](const IsoDirection& at, std::span<double> out) {
    if (at.theta_i > 50) return interp::InterpStatus::kOutsideHull;
    for (std::size_t b = 0; b < out.size(); ++b) {
      out[b] = 0.1 + 0.001 * at.theta_o + 0.0001 * at.phi + 0.01 * static_cast<double>(b);
    }
    return interp::InterpStatus::kOk;
  };
  Result<MerlExport> one = BuildMerlTable(source, grid, w, RunControl{1, {}}, LongContext());
  Result<MerlExport> two = BuildMerlTable(source, grid, w, RunControl{3, {}}, LongContext());
  ASSERT_TRUE(one.ok() && two.ok());
  EXPECT_EQ(std::memcmp(one->table.stored.data(), two->table.stored.data(),
                        one->table.stored.size() * sizeof(double)),
            0);
  std::size_t expect_unfilled = 0;
  for (std::size_t cell = 0; cell < kMerlCells; ++cell) {
    const int k = static_cast<int>(cell % 180), j = static_cast<int>(cell / 180 % 90),
              i = static_cast<int>(cell / 180 / 90);
    const MerlCellDirections c = CellDirections(i, j, k);
    if (c.above && ToIsotropic(c.directions).theta_i > 50) {
      ++expect_unfilled;
      EXPECT_EQ(one->table.stored[cell], kMerlMissing);
    }
  }
  EXPECT_EQ(one->report.unfilled.at(interp::InterpStatus::kOutsideHull), expect_unfilled);
  EXPECT_EQ(one->report.filled + one->report.below_horizon + expect_unfilled, kMerlCells);
  EXPECT_NE(one->report.Summary().find("outside_hull"), std::string::npos);
}

TEST(MerlReader, RejectsFilesOfTheWrongShape) {
  EXPECT_EQ(ParseMerl("short").status().code(), StatusCode::kInvalidArgument);
  std::string bad(kMerlFileBytes, '\0');
  const std::int32_t dims[3] = {90, 90, 360};
  std::memcpy(bad.data(), dims, 12);
  Result<MerlTable> r = ParseMerl(bad);
  ASSERT_FALSE(r.ok());
  EXPECT_NE(r.status().message().find("90 × 90 × 360"), std::string::npos);
  const std::int32_t good[3] = {90, 90, 180};
  std::memcpy(bad.data(), good, 12);
  EXPECT_TRUE(ParseMerl(bad).ok());
  bad.push_back('x');
  EXPECT_EQ(ParseMerl(bad).status().code(), StatusCode::kInvalidArgument);
}

}  // namespace
}  // namespace brdf::exports
