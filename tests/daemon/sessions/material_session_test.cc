// A session on a material file, end to end: brdf-sim mounts deploy/materials/gold.toml (a GGX
// conductor with gold's n and k) with its meter's noise as configured (the defaults: shot noise
// and read noise, no other error source), brdfd records a grid of readings through its real
// drivers, and every reading's BRDF, recomputed from the raw spectra it stored, matches what
// `brdf-sim truth --material gold.toml` prints at the reading's directions within that noise:
//   |f − truth| ≤ 5 σf + q   in every band,
// where σf propagates the detector's noise model (tools/brdf-sim/optics/detector.h) and the meter's
// 4-digit printout through f = (I − D) / (I0 − D) · ρw / π · cos θi,ref / cos θi, and q bounds
// the stage's quantisation (half a count, 0.018°, on each axis) through the truth's own slope.
// The errors normalised by σf must also spread as the noise does (RMS near 1): the readings are
// no noisier, and no smoother, than configured.
#include <gtest/gtest.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <map>
#include <memory>
#include <string>
#include <vector>

#include "core/geometry.h"
#include "tests/daemon/interpolation/derived_readings.h"
#include "tests/support/daemon/rig_teardown.h"
#include "tests/support/daemon/test_rig.h"
#include "tests/support/plan_fixtures.h"
#include "tools/brdf-sim/optics/detector.h"
#include "tools/brdf-sim/optics/material.h"

namespace brdf::testing {
namespace {

using namespace std::chrono_literals;

const std::string kGold = std::string(BRDF_TEST_SOURCE_DIR) + "/deploy/materials/gold.toml";

// Half a count of the simulated drives (10000 counts per turn).
constexpr double kHalfCountDeg = 0.5 * 360.0 / 10000.0;
// The meter prints 4 significant digits: a rounding of at most 5e-4 of the value, uniform, so a
// standard deviation of 5e-4 / √3 of it.
constexpr double kPrintRounding = 5e-4 / 1.7320508075688772;

std::string Num(double x) {
  char buf[40];
  std::snprintf(buf, sizeof buf, "%.17g", x);
  return buf;
}

// `brdf-sim truth --material gold.toml` at `d`, as the process prints it.
std::vector<double> PrintedTruth(const Directions& d) {
  Result<CommandResult> r =
      RunBrdfSim({"truth", "--material", kGold, "--theta-i", Num(d.theta_i), "--phi-i",
                  Num(d.phi_i), "--theta-o", Num(d.theta_o), "--phi-o", Num(d.phi_o), "--json"});
  EXPECT_TRUE(r.ok() && r->exit_code == 0) << (r.ok() ? r->err : r.status().ToString());
  std::vector<double> out;
  if (!r.ok()) return out;
  const std::size_t start = r->out.find("\"brdf\":[");
  if (start == std::string::npos) return out;
  const char* p = r->out.c_str() + start + 8;
  while (*p != ']' && *p != '\0') {
    char* end = nullptr;
    out.push_back(std::strtod(p, &end));
    p = *end == ',' ? end + 1 : end;
  }
  return out;
}

// The integration time the meter used: the reading's, or, when the meter chose it (adaptive: the
// reading says 0), the one brdf-sim's detector picks for the reading's brightest band.
int IntegrationMs(const sim::Detector& detector, const v1::Reading& r) {
  if (r.integration_ms() > 0) return static_cast<int>(r.integration_ms());
  const double peak = *std::max_element(r.radiance().begin(), r.radiance().end());
  return detector.ChooseExposure(peak, sim::MeterSetup{}).integration_ms;
}

// One band's variance of a raw reading: the detector's noise and the printout's rounding.
double Variance(const sim::Detector& detector, const v1::Reading& r, int band) {
  const double x = r.radiance(band);
  const double noise = detector.NoiseSigma(x, IntegrationMs(detector, r),
                                           static_cast<int>(std::max(1u, r.averages())));
  return noise * noise + (kPrintRounding * x) * (kPrintRounding * x);
}

// σ of f = (I − D) / (I0 − D) · c in one band, by first-order propagation (D enters both).
double BrdfSigma(const sim::Detector& det, const v1::Reading& sample, const v1::Reading& white,
                 const v1::Reading& dark, int b, double c) {
  const double i = sample.radiance(b), i0 = white.radiance(b), d = dark.radiance(b);
  const double w = i0 - d;
  const double df_di = c / w, df_di0 = -c * (i - d) / (w * w), df_dd = c * (i - i0) / (w * w);
  return std::sqrt(df_di * df_di * Variance(det, sample, b) +
                   df_di0 * df_di0 * Variance(det, white, b) +
                   df_dd * df_dd * Variance(det, dark, b));
}

// The most the truth moves in each band when each axis moves by half a count either way.
std::vector<double> QuantisationBound(const material::Material& m, const Pose& pose) {
  const WavelengthGrid grid = WavelengthGrid::Pr650();
  const std::vector<double> at = m.EvaluateSpectrum(PoseToDirections(pose), grid);
  std::vector<double> bound(grid.count, 0.0);
  for (int axis = 0; axis < 4; ++axis) {
    for (double sign : {-1.0, 1.0}) {
      Pose moved = pose;
      double* angles[] = {&moved.alpha, &moved.beta, &moved.gamma, &moved.delta};
      *angles[axis] += sign * kHalfCountDeg;
      const std::vector<double> f = m.EvaluateSpectrum(PoseToDirections(moved), grid);
      for (std::size_t k = 0; k < grid.count; ++k) {
        bound[k] = std::max(bound[k], std::abs(f[k] - at[k]));
      }
    }
  }
  return bound;
}

class MaterialSessionTest : public ::testing::Test {
 protected:
  void SetUp() override {
    Status sim = rig_.StartSim({"--material", kGold});
    ASSERT_TRUE(sim.ok()) << sim.ToString();
    Status daemon = rig_.StartDaemon();
    ASSERT_TRUE(daemon.ok()) << daemon.ToString();
  }
  void TearDown() override {
    if (op_) {
      op_->Stop();
      for (const std::string& e : op_->errors()) ADD_FAILURE() << "operator: " << e;
    }
    StopDaemonExpectingCleanExit(rig_);
  }

  DaemonRig rig_;
  std::unique_ptr<GrpcOperator> op_;
};

TEST_F(MaterialSessionTest, ReadingsOfGoldMatchBrdfSimTruthWithinTheConfiguredNoise) {
  Result<v1::Session> submitted = rig_.Submit(plans::InterpolationGrid().Retry(2, 0));
  ASSERT_TRUE(submitted.ok()) << submitted.status().ToString();
  const std::string id = submitted->session_id();
  op_ = std::make_unique<GrpcOperator>(rig_, id);
  const v1::Session done = rig_.WaitForState(id, v1::SESSION_STATE_COMPLETED, 90s);
  ASSERT_EQ(done.state(), v1::SESSION_STATE_COMPLETED) << done.DebugString();
  Result<std::vector<v1::Reading>> all = rig_.Readings(id);
  ASSERT_TRUE(all.ok()) << all.status().ToString();
  std::map<std::int64_t, v1::Reading> by_id;
  for (const auto& r : *all) by_id[r.id()] = r;

  Result<material::Material> gold = sim::LoadMaterialFile(kGold);
  ASSERT_TRUE(gold.ok()) << gold.status().ToString();
  const sim::Detector detector{sim::DetectorConfig{}};
  int samples = 0, near_mirror = 0;
  double sum_z2 = 0;
  int z_count = 0;
  for (const auto& [rid, r] : by_id) {
    if (r.kind() != v1::READING_KIND_SAMPLE) continue;
    ++samples;
    const DerivedReading d = DeriveReading(r, by_id);
    const std::vector<double> truth = PrintedTruth(d.directions);
    ASSERT_EQ(truth.size(), d.brdf.size());
    // The printed truth is the material itself.
    ASSERT_EQ(truth, gold->EvaluateSpectrum(d.directions, WavelengthGrid::Pr650()));
    const v1::Reading& white = by_id.at(r.reference_id());
    ASSERT_NE(r.dark_id(), 0);
    const v1::Reading& dark = by_id.at(r.dark_id());
    const Pose pose{r.pose().alpha(), r.pose().beta(), r.pose().gamma(), r.pose().delta()};
    const std::vector<double> q = QuantisationBound(*gold, pose);
    const double c = d.brdf[50] / (d.radiance[50] / (white.radiance(50) - dark.radiance(50)));
    if (truth[50] > 1.0) ++near_mirror;
    for (int b = 0; b < r.radiance_size(); ++b) {
      const double sigma = BrdfSigma(detector, r, white, dark, b, c);
      const double err = d.brdf[static_cast<std::size_t>(b)] - truth[static_cast<std::size_t>(b)];
      EXPECT_LE(std::abs(err), 5 * sigma + q[static_cast<std::size_t>(b)])
          << "reading " << rid << " (" << r.label() << ") at " << 380 + 4 * b << " nm: f "
          << d.brdf[static_cast<std::size_t>(b)] << ", truth " << truth[static_cast<std::size_t>(b)]
          << ", σ " << sigma << ", quantisation " << q[static_cast<std::size_t>(b)];
      if (q[static_cast<std::size_t>(b)] < 0.2 * sigma) {
        sum_z2 += (err / sigma) * (err / sigma);
        ++z_count;
      }
    }
  }
  EXPECT_GE(samples, 20);
  EXPECT_GE(near_mirror, 1) << "the grid should see gold's highlight at least once";
  ASSERT_GE(z_count, 500);
  const double rms = std::sqrt(sum_z2 / z_count);
  RecordProperty("normalised_rms", std::to_string(rms));
  EXPECT_GT(rms, 0.7) << "errors smaller than the configured noise";
  EXPECT_LT(rms, 1.3) << "errors larger than the configured noise";
}

}  // namespace
}  // namespace brdf::testing
