// A material file mounted in brdf-sim: the optics draw the meter's readings from it, `brdf-sim
// truth` prints it (in process and as a process, with --material before or after `truth`, or
// from --config), a run with one starts up, and a bad file stops brdf-sim with its line and key.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdlib>
#include <fstream>
#include <numbers>
#include <string>
#include <vector>

#include "core/geometry.h"
#include "tests/support/sim/process.h"
#include "tests/support/test_env.h"
#include "tools/brdf-sim/optics/material.h"
#include "tools/brdf-sim/optics/optics.h"
#include "tools/brdf-sim/optics/truth.h"

namespace brdf::sim {
namespace {

using brdf::testing::RunBrdfSim;

std::string Shipped(const std::string& name) {
  return std::string(BRDF_TEST_SOURCE_DIR) + "/deploy/materials/" + name;
}

material::Material Gold() {
  Result<material::Material> m = LoadMaterialFile(Shipped("gold.toml"));
  EXPECT_TRUE(m.ok()) << m.status().ToString();
  return m.ok() ? *m : material::Material();
}

// The numbers of the JSON array "brdf" in `json`.
std::vector<double> BrdfArray(const std::string& json) {
  std::vector<double> out;
  const std::size_t start = json.find("\"brdf\":[");
  if (start == std::string::npos) return out;
  const char* p = json.c_str() + start + 8;
  while (*p != ']' && *p != '\0') {
    char* end = nullptr;
    out.push_back(std::strtod(p, &end));
    p = *end == ',' ? end + 1 : end;
  }
  return out;
}

class FixedStage final : public StagePoseSource {
 public:
  Pose LivePose() const override { return pose; }
  Pose pose;
};

TEST(MaterialSampleTest, TheOpticsDrawReadingsFromTheMountedMaterial) {
  OpticsConfig cfg;
  cfg.noise_scale = 0;
  cfg.material_path = Shipped("gold.toml");
  ASSERT_TRUE(LoadMountedMaterial(cfg).ok());
  FixedStage stage;
  SimControl control;
  RigOptics optics(stage, control, cfg);
  EXPECT_EQ(optics.sample().name(), "gold (rough)");
  const material::Material gold = Gold();
  const WavelengthGrid grid = WavelengthGrid::Pr650();
  // The reduction of a noiseless sample, white and dark gives back the material, near the mirror
  // and off it.
  const Pose reference{0, 10, 0, 0};
  control.set_mounted(MountedTarget::kDark);
  stage.pose = reference;
  const SimMeasurement dark = optics.Measure({100, 1});
  control.set_mounted(MountedTarget::kWhite);
  const SimMeasurement white = optics.Measure({100, 1});
  control.set_mounted(MountedTarget::kSample);
  for (const Pose& pose : {Pose{0, 25, 0, 50}, Pose{10, 20, 0, 60}, Pose{20, 35, 30, 70}}) {
    stage.pose = pose;
    const SimMeasurement s = optics.Measure({0, 1});
    const Directions d = PoseToDirections(pose);
    const double cos_ratio =
        std::cos(PoseToDirections(reference).theta_i * std::numbers::pi / 180) /
        std::cos(d.theta_i * std::numbers::pi / 180);
    const std::vector<double> truth = gold.EvaluateSpectrum(d, grid);
    for (std::size_t k = 0; k < grid.count; k += 4) {
      const double f = (s.radiance[k] - dark.radiance[k]) / (white.radiance[k] - dark.radiance[k]) *
                       0.99 / std::numbers::pi * cos_ratio;
      EXPECT_NEAR(f, truth[k], 1e-9 * truth[k]) << grid.at(k) << " nm";
    }
  }
}

TEST(MaterialSampleTest, TruthTakesTheRunsSampleUnlessTheQueryNamesOne) {
  OpticsConfig run;
  run.material_path = Shipped("gold.toml");
  TruthQuery q;
  q.directions = {30, 0, 30, 180};
  Result<material::Material> s = TruthSample(q, run);
  ASSERT_TRUE(s.ok()) << s.status().ToString();
  EXPECT_EQ(s->name(), "gold (rough)");
  q.glossy = true;
  s = TruthSample(q, run);
  ASSERT_TRUE(s.ok()) << s.status().ToString();
  EXPECT_EQ(s->name(), "glossy");
  q.glossy = false;
  q.material_path = Shipped("clay.toml");
  EXPECT_EQ(TruthSample(q, OpticsConfig{})->name(), "terracotta (Oren-Nayar)");
  q.anisotropic = true;
  EXPECT_EQ(TruthSample(q, run).status().code(), StatusCode::kInvalidArgument);
  // The JSON names the material and its anisotropy.
  TruthQuery j;
  j.directions = {30, 0, 30, 180};
  j.json = true;
  const std::string json = FormatTruth(j, *LoadMaterialFile(Shipped("brushed-aluminium.toml")));
  EXPECT_NE(json.find("\"sample\":\"brushed aluminium\""), std::string::npos) << json;
  EXPECT_NE(json.find("\"anisotropic\":true"), std::string::npos) << json;
}

TEST(MaterialSampleTest, TruthProcessPrintsTheMaterialExactly) {
  const Directions d{35, 10, 40, 200};
  const std::vector<double> gold = Gold().EvaluateSpectrum(d, WavelengthGrid::Pr650());
  const std::vector<std::string> query = {"--theta-i", "35",      "--phi-i", "10",    "--theta-o",
                                          "40",        "--phi-o", "200",     "--json"};
  // --material before `truth` (as for a run), and after it.
  std::vector<std::string> before = {"--material", Shipped("gold.toml"), "truth"};
  before.insert(before.end(), query.begin(), query.end());
  std::vector<std::string> after = {"truth", "--material", Shipped("gold.toml")};
  after.insert(after.end(), query.begin(), query.end());
  // And from a --config file naming it relative to the file.
  testing::TempDir dir;
  const std::string config = dir.file("sim.toml").string();
  std::ofstream(config) << "material = \"" << Shipped("gold.toml") << "\"\n";
  std::vector<std::string> from_config = {"--config", config, "truth"};
  from_config.insert(from_config.end(), query.begin(), query.end());
  for (const auto& args : {before, after, from_config}) {
    auto r = RunBrdfSim(args);
    ASSERT_TRUE(r.ok()) << r.status().ToString();
    ASSERT_EQ(r->exit_code, 0) << r->err;
    EXPECT_EQ(BrdfArray(r->out), gold) << args[0];
    EXPECT_NE(r->out.find("\"sample\":\"gold (rough)\""), std::string::npos) << r->out;
  }
}

TEST(MaterialSampleTest, ABadMaterialFileStopsBrdfSimWithItsLineAndKey) {
  testing::TempDir dir;
  const std::string bad = dir.file("bad.toml").string();
  std::ofstream(bad) << "[[lobe]]\ntype = \"ggx\"\nroughness = 0.2\nfresnel = \"conductor\"\n";
  for (const std::vector<std::string>& args :
       {std::vector<std::string>{"--material", bad, "--time-scale", "50"},
        std::vector<std::string>{"truth", "--material", bad, "--theta-i", "0", "--theta-o", "0"}}) {
    auto r = RunBrdfSim(args);
    ASSERT_TRUE(r.ok()) << r.status().ToString();
    EXPECT_EQ(r->exit_code, 2);
    EXPECT_NE(r->err.find("material file " + bad + ": line 1, column 1: lobe[0].n: missing"),
              std::string::npos)
        << r->err;
    EXPECT_TRUE(r->out.empty()) << "nothing on stdout: " << r->out;
  }
  auto missing = RunBrdfSim({"--material", dir.file("nope.toml").string()});
  ASSERT_TRUE(missing.ok());
  EXPECT_EQ(missing->exit_code, 2);
  EXPECT_NE(missing->err.find("cannot be opened"), std::string::npos) << missing->err;
}

TEST(MaterialSampleTest, ARunWithAMaterialStartsUp) {
  auto sim =
      testing::SimProcess::Start({"--material", Shipped("retro-coating.toml"), "--time-scale", "50",
                                  "--no-pacing", "--wake-window", "0", "--log-level", "warn"});
  ASSERT_TRUE(sim.ok()) << sim.status().ToString();
  EXPECT_EQ((*sim)->startup_lines().back(), "ready");
}

}  // namespace
}  // namespace brdf::sim
