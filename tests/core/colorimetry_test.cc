#include "core/colorimetry.h"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <cmath>
#include <fstream>
#include <sstream>
#include <string>

namespace brdf {
namespace {

using ::testing::ElementsAre;
using ::testing::HasSubstr;

// colord-data is a declared dependency (deploy/install-deps.sh); the core parses text, the test
// is the caller that reads the file.
std::string ReadColordFile(const std::string& relative) {
  const std::string path = "/usr/share/colord/" + relative;
  std::ifstream in(path);
  EXPECT_TRUE(in.good()) << "cannot read " << path << "; install the colord-data package";
  std::ostringstream s;
  s << in.rdbuf();
  return s.str();
}

SpectralTable LoadTable(const std::string& relative) {
  Result<SpectralTable> t = ParseSpectralTable(ReadColordFile(relative));
  EXPECT_TRUE(t.ok()) << relative << ": " << t.status().ToString();
  return t.ok() ? std::move(t).value() : SpectralTable{};
}

ColorMatchingFunctions Cie1931() {
  Result<ColorMatchingFunctions> cmf =
      ColorMatchingFunctionsFromTable(LoadTable("cmf/CIE1931-2deg-XYZ.cmf"));
  EXPECT_TRUE(cmf.ok()) << cmf.status().ToString();
  return cmf.ok() ? std::move(cmf).value() : ColorMatchingFunctions{};
}

Spectrum Illuminant(const std::string& name) {
  Result<Spectrum> s = LoadTable("illuminant/" + name + ".sp").SetAsSpectrum(0);
  EXPECT_TRUE(s.ok()) << s.status().ToString();
  return s.ok() ? std::move(s).value() : Spectrum{};
}

constexpr const char* kSmallTable = R"(SPECT
# a comment line
DISPLAY	"Two samples"
ORIGINATOR	"hand-made"
NUMBER_OF_FIELDS	4
NUMBER_OF_SETS	2
BEGIN_DATA_FORMAT
SAMPLE_ID	SPEC_400	SPEC_410
SPEC_420
END_DATA_FORMAT
BEGIN_DATA
"first one"	0.5	0.25	1e-3
S2	1	2
3
END_DATA
)";

TEST(ColorimetryTest, ParsesSmallTable) {
  const Result<SpectralTable> t = ParseSpectralTable(kSmallTable);
  ASSERT_TRUE(t.ok()) << t.status().ToString();
  EXPECT_EQ(t->kind, "SPECT");
  EXPECT_EQ(t->name, "Two samples");
  EXPECT_THAT(t->wavelengths_nm, ElementsAre(400, 410, 420));
  EXPECT_THAT(t->set_ids, ElementsAre("first one", "S2"));
  ASSERT_EQ(t->sets.size(), 2u);
  EXPECT_THAT(t->sets[0], ElementsAre(0.5, 0.25, 1e-3));
  EXPECT_THAT(t->sets[1], ElementsAre(1, 2, 3));
  const Result<Spectrum> s = t->SetAsSpectrum(1);
  ASSERT_TRUE(s.ok()) << s.status().ToString();
  EXPECT_EQ(s->grid, (WavelengthGrid{400, 10, 3}));
  EXPECT_FALSE(t->SetAsSpectrum(2).ok());
}

TEST(ColorimetryTest, ParseErrorsNameTheLine) {
  std::string text = kSmallTable;
  text.replace(text.find("0.25"), 4, "0.2x");
  Result<SpectralTable> t = ParseSpectralTable(text);
  ASSERT_FALSE(t.ok());
  EXPECT_EQ(t.status().code(), StatusCode::kInvalidArgument);
  EXPECT_THAT(t.status().message(), HasSubstr("line 12"));
  EXPECT_THAT(t.status().message(), HasSubstr("'0.2x' of field SPEC_410 in set 1"));

  text = kSmallTable;
  text.replace(text.find("NUMBER_OF_SETS\t2"), 16, "NUMBER_OF_SETS\t3");
  t = ParseSpectralTable(text);
  ASSERT_FALSE(t.ok());
  EXPECT_THAT(t.status().message(), HasSubstr("NUMBER_OF_SETS says 3"));

  text = kSmallTable;
  text.replace(text.find("\n3\n"), 3, "\n");
  t = ParseSpectralTable(text);
  ASSERT_FALSE(t.ok());
  EXPECT_THAT(t.status().message(), HasSubstr("do not fill whole sets"));

  t = ParseSpectralTable("SPECT\nBEGIN_DATA\n1 2\nEND_DATA\n");
  ASSERT_FALSE(t.ok());
  EXPECT_THAT(t.status().message(), HasSubstr("line 2"));
  t = ParseSpectralTable(
      "SPECT\nBEGIN_DATA_FORMAT\nSAMPLE_ID\nEND_DATA_FORMAT\nBEGIN_DATA\nA\nEND_DATA");
  ASSERT_FALSE(t.ok());
  EXPECT_THAT(t.status().message(), HasSubstr("no SPEC_"));
  EXPECT_FALSE(ParseSpectralTable("").ok());
  EXPECT_FALSE(ParseSpectralTable("SPECT\nBEGIN_DATA_FORMAT\nSPEC_400\n").ok());
}

TEST(ColorimetryTest, HeaderRangeOverridesFieldNames) {
  // As in colord's CIE-A.sp: fields named in thousandths of a nm, the header in nm.
  constexpr const char* kText = R"(SPECT
SPECTRAL_START_NM	300.0
SPECTRAL_END_NM	302.0
SPECTRAL_BANDS	3
BEGIN_DATA_FORMAT
SPEC_300000	SPEC_301000	SPEC_302000
END_DATA_FORMAT
BEGIN_DATA
1 2 3
END_DATA
)";
  const Result<SpectralTable> t = ParseSpectralTable(kText);
  ASSERT_TRUE(t.ok()) << t.status().ToString();
  EXPECT_THAT(t->wavelengths_nm, ElementsAre(300, 301, 302));
  std::string text = kText;
  text.replace(text.find("BANDS\t3"), 7, "BANDS\t4");
  const Result<SpectralTable> bad = ParseSpectralTable(text);
  ASSERT_FALSE(bad.ok());
  EXPECT_THAT(bad.status().message(), HasSubstr("SPECTRAL_BANDS says 4"));
}

TEST(ColorimetryTest, EveryColordTableParses) {
  for (const char* file :
       {"cmf/CIE1931-2deg-XYZ.cmf", "cmf/CIE1964-10deg-XYZ.cmf", "ref/CIE-1986-daylight-SPD.cmf",
        "ref/CIE-TCS.sp", "illuminant/CIE-A.sp", "illuminant/CIE-B.sp", "illuminant/CIE-C.sp",
        "illuminant/CIE-D50.sp", "illuminant/CIE-D55.sp", "illuminant/CIE-D65.sp",
        "illuminant/CIE-D93.sp", "illuminant/CIE-E.sp", "illuminant/CIE-F2.sp",
        "illuminant/CIE-F11.sp"}) {
    const SpectralTable t = LoadTable(file);
    ASSERT_FALSE(t.sets.empty()) << file;
    for (std::size_t i = 0; i < t.sets.size(); ++i) {
      const Result<Spectrum> s = t.SetAsSpectrum(i);
      EXPECT_TRUE(s.ok()) << file << " set " << i << ": " << s.status().ToString();
      if (s.ok()) {
        EXPECT_GE(s->grid.start_nm, 300) << file;
        EXPECT_LE(s->grid.last_nm(), 830 + 1e-9) << file;
      }
    }
  }
}

TEST(ColorimetryTest, UnevenWavelengthsAreNotASpectrum) {
  SpectralTable t;
  t.wavelengths_nm = {400, 410, 425};
  t.sets = {{1, 2, 3}};
  const Result<Spectrum> s = t.SetAsSpectrum(0);
  ASSERT_FALSE(s.ok());
  EXPECT_THAT(s.status().message(), HasSubstr("not evenly spaced"));
}

TEST(ColorimetryTest, ParsesColordFiles) {
  const Spectrum d65 = Illuminant("CIE-D65");
  EXPECT_EQ(d65.grid, (WavelengthGrid{300, 5, 107}));
  EXPECT_EQ(d65.values[(560 - 300) / 5], 1.0);  // D65 is normalised to 1 at 560 nm here
  const ColorMatchingFunctions cmf = Cie1931();
  EXPECT_EQ(cmf.y_bar.grid, (WavelengthGrid{360, 5, 95}));
  EXPECT_EQ(cmf.y_bar.values[(555 - 360) / 5], 1.0);  // ȳ peaks at 555 nm
  const SpectralTable tcs = LoadTable("ref/CIE-TCS.sp");
  EXPECT_EQ(tcs.sets.size(), 15u);
  ASSERT_EQ(tcs.set_ids.size(), 15u);
  EXPECT_EQ(tcs.set_ids[0], "TCS01");
  EXPECT_EQ(tcs.wavelengths_nm.size(), 95u);
}

TEST(ColorimetryTest, PerfectWhiteUnderD65IsD65WhitePoint) {
  const ColorMatchingFunctions cmf = Cie1931();
  const Spectrum d65 = Illuminant("CIE-D65");
  for (const WavelengthGrid& grid : {WavelengthGrid::Pr650(), WavelengthGrid{380, 5, 81}}) {
    const Result<Xyz> white = WhitePoint(d65, cmf, grid);
    ASSERT_TRUE(white.ok()) << white.status().ToString();
    EXPECT_DOUBLE_EQ(white->Y, 1.0);
    const Result<Chromaticity> xy = ToChromaticity(*white);
    ASSERT_TRUE(xy.ok());
    EXPECT_NEAR(xy->x, 0.3127, 5e-4);
    EXPECT_NEAR(xy->y, 0.3290, 5e-4);
    // sRGB's white is D65: the perfect white is (1, 1, 1).
    const Rgb linear = XyzToLinearSrgb(*white);
    EXPECT_NEAR(linear.r, 1.0, 5e-3);
    EXPECT_NEAR(linear.g, 1.0, 5e-3);
    EXPECT_NEAR(linear.b, 1.0, 5e-3);
    const Rgb encoded = EncodeSrgb(linear);
    EXPECT_NEAR(encoded.r, 1.0, 5e-3);
    EXPECT_NEAR(encoded.g, 1.0, 5e-3);
    EXPECT_NEAR(encoded.b, 1.0, 5e-3);
  }
}

TEST(ColorimetryTest, IlluminantAWhitePoint) {
  const Result<Xyz> white = WhitePoint(Illuminant("CIE-A"), Cie1931(), WavelengthGrid{380, 5, 81});
  ASSERT_TRUE(white.ok()) << white.status().ToString();
  const Result<Chromaticity> xy = ToChromaticity(*white);
  ASSERT_TRUE(xy.ok());
  EXPECT_NEAR(xy->x, 0.4476, 5e-4);
  EXPECT_NEAR(xy->y, 0.4074, 5e-4);
}

TEST(ColorimetryTest, GreyIsScaledWhiteAndRedPaintIsRed) {
  const ColorMatchingFunctions cmf = Cie1931();
  const Spectrum d65 = Illuminant("CIE-D65");
  const WavelengthGrid grid = WavelengthGrid::Pr650();
  const Result<Xyz> white = WhitePoint(d65, cmf, grid);
  const Result<Xyz> grey =
      ReflectanceToXyz({grid, std::vector<double>(grid.count, 0.18)}, d65, cmf);
  ASSERT_TRUE(white.ok());
  ASSERT_TRUE(grey.ok());
  EXPECT_NEAR(grey->X, 0.18 * white->X, 1e-12);
  EXPECT_NEAR(grey->Y, 0.18, 1e-12);
  EXPECT_NEAR(grey->Z, 0.18 * white->Z, 1e-12);

  Spectrum red{grid, std::vector<double>(grid.count)};
  for (std::size_t k = 0; k < grid.count; ++k) red.values[k] = grid.at(k) > 600 ? 0.8 : 0.05;
  const Result<Xyz> xyz = ReflectanceToXyz(red, d65, cmf);
  ASSERT_TRUE(xyz.ok());
  const Rgb rgb = XyzToLinearSrgb(*xyz);
  EXPECT_GT(rgb.r, 3 * rgb.g);
  EXPECT_GT(rgb.r, 3 * rgb.b);
}

TEST(ColorimetryTest, RejectsUncoveredGridAndBlack) {
  const Spectrum wide{{300, 10, 61}, std::vector<double>(61, 1.0)};  // 300–900 nm
  const Result<Xyz> xyz = ReflectanceToXyz(wide, Illuminant("CIE-D65"), Cie1931());
  ASSERT_FALSE(xyz.ok());
  EXPECT_EQ(xyz.status().code(), StatusCode::kInvalidArgument);
  EXPECT_THAT(xyz.status().message(), HasSubstr("illuminant"));
  const Result<Chromaticity> black = ToChromaticity({0, 0, 0});
  ASSERT_FALSE(black.ok());
  EXPECT_THAT(black.status().message(), HasSubstr("black"));
}

TEST(ColorimetryTest, SrgbTransferFunction) {
  EXPECT_EQ(EncodeSrgbComponent(0), 0);
  EXPECT_DOUBLE_EQ(EncodeSrgbComponent(1), 1);
  EXPECT_NEAR(EncodeSrgbComponent(0.0031308), 0.04045, 1e-5);  // the two pieces meet
  EXPECT_NEAR(EncodeSrgbComponent(0.5), 0.735357, 1e-6);
  EXPECT_NEAR(EncodeSrgbComponent(0.18), 0.461356, 1e-6);
  EXPECT_DOUBLE_EQ(EncodeSrgbComponent(1.7), 1);
  EXPECT_EQ(EncodeSrgbComponent(-0.2), 0);
  // Pure sRGB primaries round-trip through the matrix: XYZ of sRGB red is (0.4124, 0.2126, 0.0193).
  const Rgb red = XyzToLinearSrgb({0.4124564, 0.2126729, 0.0193339});
  EXPECT_NEAR(red.r, 1, 1e-6);
  EXPECT_NEAR(red.g, 0, 1e-6);
  EXPECT_NEAR(red.b, 0, 1e-6);
}

}  // namespace
}  // namespace brdf
