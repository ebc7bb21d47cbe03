// Finer candidates: only near the readings and the best coarse candidates, never a known pose,
// always reachable, deterministic; and with them a round gets nearer to a narrow peak.
#include "core/adaptive/refine_candidates.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <vector>

#include "core/adaptive/candidates.h"
#include "core/adaptive/round_chooser.h"
#include "core/geometry.h"
#include "kernel_model.h"

namespace brdf::adaptive {
namespace {

using testing::IsoDistanceSquared;
using testing::KernelModel;

// A narrow peak between the 10° lattice's poses.
constexpr IsoDirection kPeak{33, 33, 180};

v1::Plan AdaptivePlan() {
  v1::Plan plan;
  plan.mutable_reference()->set_per_detector_position(false);
  v1::Adaptive* a = plan.mutable_adaptive();
  a->mutable_region()->set_theta_i_max_deg(75);
  a->mutable_region()->set_theta_o_max_deg(75);
  a->mutable_delta()->set_start(0);
  a->mutable_delta()->set_stop(90);
  a->mutable_delta()->set_step(22.5);
  return plan;
}

plan::RigDescription Arm() {
  plan::RigDescription arm;
  arm.has_detector_arm = true;
  return arm;
}

KernelModel Narrow() {
  return KernelModel(
      [](const IsoDirection& d) {
        return 0.01 + std::exp(-IsoDistanceSquared(d, kPeak) / (2 * 4 * 4));
      },
      /*sigma=*/3, /*share=*/0.9);
}

double BetaGap(double a, double b) {
  const double d = std::fabs(a - b);
  return std::min(d, 360 - d);
}

// Within `reach` in α and β of one of `anchors` at the same (δ, γ).
bool Near(const Pose& p, const std::vector<Pose>& anchors, double reach) {
  return std::any_of(anchors.begin(), anchors.end(), [&](const Pose& a) {
    return a.delta == p.delta && a.gamma == p.gamma &&
           std::fabs(a.alpha - p.alpha) <= reach + 1e-6 && BetaGap(a.beta, p.beta) <= reach + 1e-6;
  });
}

std::vector<ReadingSoFar> SomeReadings(const std::vector<Pose>& candidates) {
  std::vector<ReadingSoFar> readings;
  for (std::size_t i = 0; i < candidates.size(); i += 5) {
    readings.push_back({candidates[i], PoseToDirections(candidates[i]), 0.1, 0.01});
  }
  return readings;
}

TEST(RefineCandidatesTest, AddsReachablePosesOnlyNearReadingsAndTheBestCandidates) {
  const v1::Plan plan = AdaptivePlan();
  const AdaptiveSpec spec = ResolveAdaptive(plan.adaptive());
  const RoundCost cost(plan, Arm());
  const std::vector<Pose> coarse = CandidatePoses(spec, Arm(), 10);
  const std::vector<ReadingSoFar> readings = SomeReadings(coarse);
  const KernelModel model = Narrow();
  const auto map = model.Map(readings);
  const RefineOptions options{.step_deg = 10, .levels = 2, .keep = 20};
  const std::vector<Pose> finer = RefinedCandidates(readings, coarse, *map, cost, options);
  ASSERT_FALSE(finer.empty());
  EXPECT_LE(finer.size(), 40u);  // keep per level
  std::vector<Pose> anchors(coarse);
  for (const ReadingSoFar& r : readings) anchors.push_back(r.pose);
  for (const Pose& p : finer) {
    EXPECT_TRUE(cost.CanReach(p));
    EXPECT_TRUE(Near(p, anchors, 5 + 2.5)) << p.alpha << " " << p.beta << " δ " << p.delta;
    EXPECT_TRUE(
        std::none_of(anchors.begin(), anchors.end(), [&](const Pose& a) { return a == p; }));
    EXPECT_GT(map->PredictedGain(PoseToDirections(p)), 0);
  }
  // Level 1 is 5° off the lattice, level 2 2.5° off level 1's: both appear.
  auto off_lattice = [](const Pose& p, double step) {
    return std::fabs(std::remainder(p.alpha, step)) > 1e-6 ||
           std::fabs(std::remainder(p.beta, step)) > 1e-6;
  };
  EXPECT_TRUE(
      std::any_of(finer.begin(), finer.end(), [&](const Pose& p) { return off_lattice(p, 5); }));
  // Where it refines is where the gains are: most finer poses lie near the peak.
  const auto near_peak = std::count_if(finer.begin(), finer.end(), [](const Pose& p) {
    return IsoDistanceSquared(ToIsotropic(PoseToDirections(p)), kPeak) < 15 * 15;
  });
  EXPECT_GE(near_peak * 2, static_cast<long>(finer.size()));
  // Deterministic, whatever the candidates' order; levels 0 adds nothing.
  const std::vector<Pose> reversed(coarse.rbegin(), coarse.rend());
  EXPECT_EQ(RefinedCandidates(readings, reversed, *map, cost, options), finer);
  EXPECT_TRUE(RefinedCandidates(readings, coarse, *map, cost, {.levels = 0}).empty());
}

TEST(RefineCandidatesTest, ARoundGetsNearerToANarrowPeakThanTheLatticeAllows) {
  const v1::Plan plan = AdaptivePlan();
  const AdaptiveSpec spec = ResolveAdaptive(plan.adaptive());
  const RoundCost cost(plan, Arm());
  const std::vector<Pose> coarse = CandidatePoses(spec, Arm(), 10);
  // Every lattice pose near the peak already measured: the lattice has nothing nearer left.
  std::vector<ReadingSoFar> readings = SomeReadings(coarse);
  for (const Pose& p : coarse) {
    if (IsoDistanceSquared(ToIsotropic(PoseToDirections(p)), kPeak) < 20 * 20) {
      readings.push_back({p, PoseToDirections(p), 0.1, 0.01});
    }
  }
  const KernelModel model = Narrow();
  const RoundInput input{readings, coarse, readings.back().pose, {}, {1000, 0, 0}};
  auto nearest = [](const Round& round) {
    double best = INFINITY;
    for (const ChosenPose& c : round.poses) {
      best = std::min(best, IsoDistanceSquared(ToIsotropic(PoseToDirections(c.pose)), kPeak));
    }
    return std::sqrt(best);
  };
  double lattice_nearest = INFINITY;
  for (const ReadingSoFar& r : readings) {
    lattice_nearest =
        std::min(lattice_nearest, std::sqrt(IsoDistanceSquared(ToIsotropic(r.directions), kPeak)));
  }
  const Round plain =
      ChooseRound(input, model, cost, {.max_readings = 8, .refine = {.step_deg = 10, .levels = 0}});
  const Round refined =
      ChooseRound(input, model, cost, {.max_readings = 8, .refine = {.step_deg = 10, .levels = 2}});
  ASSERT_FALSE(refined.poses.empty());
  EXPECT_LT(nearest(refined), lattice_nearest);
  EXPECT_LT(nearest(refined), plain.poses.empty() ? INFINITY : nearest(plain));
  EXPECT_GT(refined.predicted_gain, plain.predicted_gain);
}

}  // namespace
}  // namespace brdf::adaptive
