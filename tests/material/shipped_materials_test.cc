// The material files brdf-sim ships (deploy/materials/): each reads without a problem; paint,
// glossy and brushed are the simulator's compiled-in samples (AnalyticBrdf) to floating-point
// tolerance at many directions and wavelengths; every file is reciprocal and conserves energy
// (directional albedo ≤ 1 at every wavelength and incidence), the glossy sample's known excess
// apart.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>
#include <vector>

#include "core/analytic_brdf.h"
#include "core/material/builtin_samples.h"
#include "core/material/directional_albedo.h"
#include "core/material/material_reader.h"

namespace brdf::material {
namespace {

std::string MaterialsDir() {
  return std::string(BRDF_TEST_SOURCE_DIR) + "/deploy/materials";
}

Material Load(const std::string& file) {
  const std::string path = MaterialsDir() + "/" + file;
  std::ifstream in(path);
  std::ostringstream text;
  text << in.rdbuf();
  Result<Material> m = ReadMaterial(text.str(), path, file);
  EXPECT_TRUE(m.ok()) << m.status().ToString();
  return m.ok() ? *m : Material();
}

std::vector<std::string> ShippedFiles() {
  std::vector<std::string> files;
  for (const auto& entry : std::filesystem::directory_iterator(MaterialsDir())) {
    if (entry.path().extension() == ".toml") files.push_back(entry.path().filename().string());
  }
  std::sort(files.begin(), files.end());
  return files;
}

// Directions over the whole upper hemisphere, θ to 90° included, azimuths all round, and the
// mirror and retro directions where lobes peak.
std::vector<Directions> ManyDirections() {
  std::vector<Directions> out;
  for (double ti = 0; ti <= 90; ti += 7.5) {
    for (double to = 0; to <= 90; to += 7.5) {
      for (double pi = -170; pi <= 180; pi += 55) {
        for (double dphi = 0; dphi < 360; dphi += 22.5) out.push_back({ti, pi, to, pi + dphi});
      }
    }
    out.push_back({ti, 30, ti, 210});  // mirror
    out.push_back({ti, 30, ti, 30});   // back at the lamp
  }
  return out;
}

void ExpectSameTruth(const Material& file, const AnalyticBrdf& compiled) {
  const WavelengthGrid fine{360, 2.5, 189};  // 360–830 nm, off the PR-650's grid too
  std::size_t compared = 0;
  for (const Directions& d : ManyDirections()) {
    const std::vector<double> a = file.EvaluateSpectrum(d, fine);
    const std::vector<double> b = compiled.EvaluateSpectrum(d, fine);
    for (std::size_t k = 0; k < fine.count; ++k, ++compared) {
      ASSERT_NEAR(a[k], b[k], 1e-12 * std::max(1.0, std::abs(b[k])))
          << file.name() << " at " << d.theta_i << " " << d.phi_i << " " << d.theta_o << " "
          << d.phi_o << ", " << fine.at(k) << " nm";
    }
  }
  EXPECT_GT(compared, 1000000u);
}

TEST(ShippedMaterialsTest, PaintGlossyAndBrushedAreTheCompiledInSamples) {
  ExpectSameTruth(Load("paint.toml"), AnalyticBrdf::PaintLike());
  ExpectSameTruth(Load("glossy.toml"), AnalyticBrdf::Glossy());
  ExpectSameTruth(Load("brushed.toml"), AnalyticBrdf::Brushed());
  EXPECT_EQ(Load("paint.toml").name(), "paint-like");
  EXPECT_TRUE(Load("brushed.toml").anisotropic());
}

TEST(ShippedMaterialsTest, BuiltInMaterialsAreTheAnalyticSamplesToTheBit) {
  // brdf-sim draws its default readings from these: they must not move a single bit.
  const WavelengthGrid grid = WavelengthGrid::Pr650();
  const std::pair<Material, AnalyticBrdf> pairs[] = {{PaintMaterial(), AnalyticBrdf::PaintLike()},
                                                     {GlossyMaterial(), AnalyticBrdf::Glossy()},
                                                     {BrushedMaterial(), AnalyticBrdf::Brushed()}};
  for (const auto& [m, a] : pairs) {
    for (const Directions& d : ManyDirections()) {
      ASSERT_EQ(m.EvaluateSpectrum(d, grid), a.EvaluateSpectrum(d, grid))
          << m.name() << " at " << d.theta_i << " " << d.phi_i << " " << d.theta_o << " "
          << d.phi_o;
      ASSERT_EQ(m.Evaluate(d, 555.5), a.Evaluate(d, 555.5));
    }
  }
}

TEST(ShippedMaterialsTest, ThereAreTheSamplesAndAHandfulMore) {
  const std::vector<std::string> files = ShippedFiles();
  for (const char* f :
       {"paint.toml", "glossy.toml", "brushed.toml", "gold.toml", "brushed-aluminium.toml",
        "retro-coating.toml", "blue-plastic.toml", "clay.toml"}) {
    EXPECT_NE(std::find(files.begin(), files.end(), f), files.end()) << f;
  }
}

TEST(ShippedMaterialsTest, EveryFileIsReciprocal) {
  for (const std::string& file : ShippedFiles()) {
    const Material m = Load(file);
    for (const Directions& d : ManyDirections()) {
      if (d.theta_i > 85 || d.theta_o > 85) continue;
      const Directions swapped{d.theta_o, d.phi_o, d.theta_i, d.phi_i};
      for (double nm : {380.0, 555.0, 780.0}) {
        const double f = m.Evaluate(d, nm), g = m.Evaluate(swapped, nm);
        ASSERT_NEAR(f, g, 1e-9 * std::max(1.0, f)) << file;
      }
    }
  }
}

// The glossy sample as compiled in (and so its file) reflects up to 0.3 % more than it
// receives at normal incidence near 610 nm: the paint's albedo 0.70 under a Blinn–Phong lobe of
// weight 0.3 whose own albedo is 0.303 there. Kept so that existing sessions and tests keep
// their truth; docs/materials.md says so.
constexpr double kGlossyExcess = 0.0035;

class ShippedMaterialEnergyTest : public ::testing::TestWithParam<std::string> {};

// On a 1° grid the midpoint rule is within 0.1 % of the narrowest shipped lobe's albedo
// (brushed aluminium's αy = 0.08), far inside every file's margin below 1.
TEST_P(ShippedMaterialEnergyTest, DirectionalAlbedoIsAtMostOneAtEveryWavelength) {
  const std::string file = GetParam();
  const Material m = Load(file);
  const WavelengthGrid grid = WavelengthGrid::Pr650();
  const double limit = file == "glossy.toml" ? 1.0 + kGlossyExcess : 1.0;
  double worst = 0;
  for (double ti : {0.0, 30.0, 60.0, 80.0, 88.0}) {
    for (double phi_i : {0.0, 60.0}) {
      if (phi_i != 0 && !m.anisotropic()) continue;
      const std::vector<double> a = DirectionalAlbedo(m, ti, phi_i, grid, 1.0);
      for (std::size_t k = 0; k < grid.count; ++k) {
        ASSERT_LE(a[k], limit) << file << " at θi " << ti << ", φi " << phi_i << ", " << grid.at(k)
                               << " nm";
        ASSERT_GE(a[k], 0.0);
        worst = std::max(worst, a[k]);
      }
    }
  }
  RecordProperty("largest_albedo", std::to_string(worst));
  if (file == "glossy.toml") {
    EXPECT_GT(worst, 1.0) << "the excess this test allows is no longer there: drop it";
  }
}

INSTANTIATE_TEST_SUITE_P(Files, ShippedMaterialEnergyTest, ::testing::ValuesIn(ShippedFiles()),
                         [](const ::testing::TestParamInfo<std::string>& param) {
                           std::string name = param.param.substr(0, param.param.find('.'));
                           std::replace(name.begin(), name.end(), '-', '_');
                           return name;
                         });

}  // namespace
}  // namespace brdf::material
