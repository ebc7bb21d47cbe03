// Reading material files: every form of a spectral value, every lobe type, and the refusals,
// each naming the file, the line and the key, and what to do.
#include "core/material/material_reader.h"

#include <gtest/gtest.h>

#include <cmath>
#include <numbers>
#include <string>

namespace brdf::material {
namespace {

constexpr double kPi = std::numbers::pi;

Result<Material> Read(const std::string& text) {
  return ReadMaterial(text, "m.toml", "m");
}

// The refusal of `text`; fails the test if it was accepted.
std::string Refusal(const std::string& text) {
  Result<Material> m = Read(text);
  EXPECT_FALSE(m.ok()) << text;
  if (m.ok()) return "";
  EXPECT_EQ(m.status().code(), StatusCode::kInvalidArgument);
  EXPECT_NE(m.status().message().find("docs/materials.md"), std::string::npos)
      << "says where the keys are described: " << m.status().message();
  return m.status().message();
}

#define EXPECT_HAS(haystack, needle) \
  EXPECT_NE((haystack).find(needle), std::string::npos) << "in: " << (haystack)

TEST(MaterialReaderTest, ReadsEveryLobeTypeAndSpectralForm) {
  Result<Material> m = Read(R"(
name = "everything"
description = "one lobe of each type"
[[lobe]]
type = "lambert"
albedo = [[400, 0.2], [700, 0.8]]
[[lobe]]
type = "oren_nayar"
albedo = 0.1
sigma_deg = 20
[[lobe]]
type = "ggx"
roughness_x = 0.1
roughness_y = 0.3
fresnel = "conductor"
n = 0.2
k = [[400, 2.0], [800, 5]]
[[lobe]]
type = "beckmann"
roughness = 0.2
fresnel = "schlick"
f0 = { base = 0.04, amplitude = 0.01, center_nm = 400, width_nm = 50 }
weight = 0.5
[[lobe]]
type = "ggx"
roughness = 0.3
fresnel = "none"
[[lobe]]
type = "blinn_phong"
exponent = 40
[[lobe]]
type = "retro"
exponent = 10
weight = 0.2
)");
  ASSERT_TRUE(m.ok()) << m.status().ToString();
  EXPECT_EQ(m->name(), "everything");
  ASSERT_EQ(m->lobes().size(), 7u);
  const char* types[] = {"lambert", "oren_nayar", "ggx", "beckmann", "ggx", "blinn_phong", "retro"};
  for (std::size_t i = 0; i < 7; ++i) EXPECT_EQ(m->lobes()[i]->type(), types[i]);
  EXPECT_TRUE(m->anisotropic());
}

TEST(MaterialReaderTest, ALambertFileGivesAlbedoOverPiAndTakesTheDefaultName) {
  Result<Material> m = Read("[[lobe]]\ntype = \"lambert\"\nalbedo = [[400, 0.2], [700, 0.8]]\n");
  ASSERT_TRUE(m.ok()) << m.status().ToString();
  EXPECT_EQ(m->name(), "m");
  EXPECT_DOUBLE_EQ(m->Evaluate({10, 0, 20, 30}, 550), 0.5 / kPi);
  EXPECT_DOUBLE_EQ(m->Evaluate({10, 0, 20, 30}, 380), 0.2 / kPi) << "held beyond the table";
}

TEST(MaterialReaderTest, NotTomlNamesTheLine) {
  const std::string e = Refusal("[[lobe]]\ntype = \"lambert\"\nalbedo = [0.2,\n");
  EXPECT_HAS(e, "material file m.toml: line");
  EXPECT_HAS(e, "not valid TOML");
}

TEST(MaterialReaderTest, AFileWithoutLobesIsRefused) {
  EXPECT_HAS(Refusal("name = \"x\"\n"), "lobe: missing; a material needs at least one [[lobe]]");
  EXPECT_HAS(Refusal("lobe = []\n"), "no lobes");
}

TEST(MaterialReaderTest, UnknownKeysAndTypesAreNamed) {
  std::string e = Refusal("nmae = \"x\"\n[[lobe]]\ntype = \"lambert\"\nalbedo = 0.5\n");
  EXPECT_HAS(e, "line 1, column 1: unknown key nmae");
  e = Refusal("[[lobe]]\ntype = \"phong\"\nalbedo = 0.5\n");
  EXPECT_HAS(e, "line 2, column 8: lobe[0].type: \"phong\" is not one of \"lambert\"");
  EXPECT_EQ(e.find("albedo"), std::string::npos) << "a lobe without a type: only the type: " << e;
  e = Refusal("[[lobe]]\ntype = \"lambert\"\nalbedo = 0.5\nexponent = 3\n");
  EXPECT_HAS(e, "line 4, column 1: unknown key lobe[0].exponent (known here: albedo, type)");
  e = Refusal("[[lobe]]\nalbedo = 0.5\n");
  EXPECT_HAS(e, "line 1, column 1: lobe[0].type: missing");
}

TEST(MaterialReaderTest, ValuesOutOfRangeAreNamedWithTheirLine) {
  std::string e = Refusal("[[lobe]]\ntype = \"lambert\"\nalbedo = 1.5\n");
  EXPECT_HAS(e, "line 3, column 10: lobe[0].albedo: 1.5 is outside [0, 1]");
  e = Refusal(
      "[[lobe]]\ntype = \"ggx\"\nfresnel = \"none\"\nroughness = 3\n"
      "[[lobe]]\ntype = \"oren_nayar\"\nalbedo = 0.5\nsigma_deg = 95\n");
  EXPECT_HAS(e, "line 4, column 13: lobe[0].roughness: 3 is outside [0.001, 2]");
  EXPECT_HAS(e, "line 8, column 13: lobe[1].sigma_deg: 95 is outside [0, 90]");
  e = Refusal(
      "[[lobe]]\ntype = \"lambert\"\n"
      "albedo = { base = 0.7, amplitude = 0.45, center_nm = 610, width_nm = 90 }\n");
  EXPECT_HAS(e, "line 3, column 10: lobe[0].albedo: base + amplitude spans 0.7 … 1.15");
}

TEST(MaterialReaderTest, TablesAreCheckedPointByPoint) {
  std::string e = Refusal(
      "[[lobe]]\ntype = \"lambert\"\nalbedo = [[400, 0.2],\n  [380, 0.3],\n  [700, 1.2],\n"
      "  [720]]\n");
  EXPECT_HAS(e,
             "line 4, column 3: lobe[0].albedo[1]: wavelengths must increase: 380 nm follows "
             "400 nm");
  EXPECT_HAS(e, "line 5, column 3: lobe[0].albedo[2]: value 1.2 at 700 nm is outside [0, 1]");
  EXPECT_HAS(e, "line 6, column 3: lobe[0].albedo[3]: must be a pair [nm, value]");
  e = Refusal("[[lobe]]\ntype = \"lambert\"\nalbedo = []\n");
  EXPECT_HAS(e, "lobe[0].albedo: an empty table");
  e = Refusal("[[lobe]]\ntype = \"lambert\"\nalbedo = \"white\"\n");
  EXPECT_HAS(e, "lobe[0].albedo: must be a number, a table of [nm, value] pairs or a bump");
  e = Refusal("[[lobe]]\ntype = \"lambert\"\nalbedo = { base = 0.2, center_nm = 500 }\n");
  EXPECT_HAS(e, "lobe[0].albedo.amplitude: missing");
  EXPECT_HAS(e, "lobe[0].albedo.width_nm: missing");
}

TEST(MaterialReaderTest, FresnelNeedsItsParametersAndOnlyThem) {
  std::string e = Refusal("[[lobe]]\ntype = \"ggx\"\nroughness = 0.2\nfresnel = \"conductor\"\n");
  EXPECT_HAS(e, "lobe[0].n: missing; fresnel = \"conductor\" needs n (and k)");
  e = Refusal("[[lobe]]\ntype = \"ggx\"\nroughness = 0.2\nfresnel = \"schlick\"\nn = 1.5\n");
  EXPECT_HAS(e, "lobe[0].f0: missing; fresnel = \"schlick\" needs f0");
  EXPECT_HAS(e, "unknown key lobe[0].n");
  e = Refusal("[[lobe]]\ntype = \"beckmann\"\nroughness = 0.2\n");
  EXPECT_HAS(e, "lobe[0].fresnel: missing; one of \"schlick\"");
  e = Refusal("[[lobe]]\ntype = \"ggx\"\nroughness = 0.2\nfresnel = \"metal\"\n");
  EXPECT_HAS(e, "lobe[0].fresnel: \"metal\" is not one of \"none\", \"schlick\", \"conductor\"");
}

TEST(MaterialReaderTest, RoughnessIsOneValueOrAPair) {
  std::string e =
      Refusal("[[lobe]]\ntype = \"ggx\"\nfresnel = \"none\"\nroughness = 0.2\nroughness_x = 0.1\n");
  EXPECT_HAS(e, "lobe[0].roughness: give either roughness or roughness_x and roughness_y");
  e = Refusal("[[lobe]]\ntype = \"ggx\"\nfresnel = \"none\"\nroughness_x = 0.1\n");
  EXPECT_HAS(e, "lobe[0].roughness_y: missing");
  e = Refusal("[[lobe]]\ntype = \"ggx\"\nfresnel = \"none\"\n");
  EXPECT_HAS(e, "lobe[0].roughness: missing; or roughness_x and roughness_y");
  e = Refusal("[[lobe]]\ntype = \"blinn_phong\"\nexponent_y = 5\n");
  EXPECT_HAS(e, "lobe[0].exponent_x: missing");
}

TEST(MaterialReaderTest, EveryProblemOfAFileIsReportedAtOnce) {
  const std::string e =
      Refusal("name = 3\n[[lobe]]\ntype = \"lambert\"\nalbedo = -1\n[[lobe]]\ntype = \"retro\"\n");
  EXPECT_HAS(e, "line 1, column 8: name: must be a string, not an integer");
  EXPECT_HAS(e, "lobe[0].albedo: -1 is outside [0, 1]");
  EXPECT_HAS(e, "lobe[1].exponent: missing");
}

}  // namespace
}  // namespace brdf::material
