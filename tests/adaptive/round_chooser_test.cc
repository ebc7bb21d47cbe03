// The round chooser: deterministic, within the budget, grouped by δ, and drawn to where the
// uncertainty is.
#include "core/adaptive/round_chooser.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <set>
#include <vector>

#include "core/adaptive/candidates.h"
#include "core/adaptive/stop_rule.h"
#include "core/geometry.h"
#include "kernel_model.h"

namespace brdf::adaptive {
namespace {

using testing::IsoDistanceSquared;
using testing::KernelModel;

// The specular peak of a glossy sample lit at 30°.
constexpr IsoDirection kPeak{30, 30, 180};

AdaptiveSpec Spec() {
  AdaptiveSpec spec;
  spec.delta_deg = {0, 22.5, 45, 67.5, 90};
  spec.region.theta_i_max_deg = 75;
  spec.region.theta_o_max_deg = 75;
  return spec;
}

std::vector<Pose> Candidates() {
  return CandidatePoses(Spec(), plan::RigDescription{}, 10);
}

v1::Plan Policies() {
  v1::Plan plan;
  plan.mutable_reference()->set_per_detector_position(true);
  return plan;
}

KernelModel Uniform() {
  return KernelModel([](const IsoDirection&) { return 0.5; });
}

KernelModel Peaked() {
  return KernelModel([](const IsoDirection& d) {
    return 0.02 + std::exp(-IsoDistanceSquared(d, kPeak) / (2 * 12 * 12));
  });
}

std::vector<Pose> Poses(const Round& round) {
  std::vector<Pose> out;
  for (const ChosenPose& p : round.poses) out.push_back(p.pose);
  return out;
}

int Prompts(const Round& round) {
  return round.cost.prompts;
}

TEST(RoundChooserTest, SameReadingsGiveTheSamePosesWhateverTheCandidateOrder) {
  const std::vector<Pose> candidates = Candidates();
  const RoundCost cost(Policies(), plan::RigDescription{});
  const KernelModel model = Peaked();
  std::vector<ReadingSoFar> readings;
  for (const Pose& p : {Pose{0, 20, 0, 0}, Pose{10, 30, 0, 45}, Pose{20, -10, 0, 22.5}}) {
    readings.push_back({p, PoseToDirections(p), 0.1, 0.01});
  }
  RoundInput input{readings, candidates, readings.back().pose, {3, 120, 6}, {200, 0, 0}};
  const Round a = ChooseRound(input, model, cost);
  const Round b = ChooseRound(input, model, cost);
  ASSERT_FALSE(a.poses.empty());
  EXPECT_EQ(Poses(a), Poses(b));
  std::vector<Pose> reversed(candidates.rbegin(), candidates.rend());
  input.candidates = reversed;
  EXPECT_EQ(Poses(ChooseRound(input, model, cost)), Poses(a));
  // A uniform field makes many scores equal: ties still resolve the same way.
  const KernelModel uniform = Uniform();
  input.candidates = candidates;
  const Round u1 = ChooseRound(input, uniform, cost);
  input.candidates = reversed;
  EXPECT_EQ(Poses(ChooseRound(input, uniform, cost)), Poses(u1));
}

TEST(RoundChooserTest, NeverChoosesAReadingsPoseOrOneTwice) {
  const std::vector<Pose> candidates = Candidates();
  const RoundCost cost(Policies(), plan::RigDescription{});
  std::vector<ReadingSoFar> readings;
  for (std::size_t i = 0; i < candidates.size(); i += 7) {
    readings.push_back({candidates[i], PoseToDirections(candidates[i]), 0.1, 0.01});
  }
  const KernelModel model = Peaked();
  const Round round =
      ChooseRound({readings, candidates, {}, {}, {1000, 0, 0}}, model, cost, {.max_readings = 40});
  std::set<std::tuple<double, double, double, double>> seen;
  for (const ChosenPose& p : round.poses) {
    EXPECT_TRUE(seen.insert({p.pose.alpha, p.pose.beta, p.pose.gamma, p.pose.delta}).second);
    for (const ReadingSoFar& r : readings) EXPECT_FALSE(r.pose == p.pose);
  }
}

TEST(RoundChooserTest, NeverChoosesAnUnreadablePose) {
  // The peak's best poses, as a first round picks them, made unreadable (the meter overloaded
  // there): the next choice from the same readings leaves them out and picks others.
  const std::vector<Pose> candidates = Candidates();
  const RoundCost cost(Policies(), plan::RigDescription{});
  const KernelModel model = Peaked();
  const Pose at{0, 10, 0, 0};
  const Round first = ChooseRound({{}, candidates, at, {}, {1000, 0, 0}}, model, cost);
  ASSERT_GE(first.poses.size(), 3u);
  const std::vector<Pose> unreadable = {first.poses[0].pose, first.poses[1].pose};
  const RoundInput input{{}, candidates, at, {}, {1000, 0, 0}, unreadable};
  const Round again = ChooseRound(input, model, cost);
  ASSERT_FALSE(again.poses.empty());
  for (const ChosenPose& p : again.poses) {
    for (const Pose& u : unreadable) EXPECT_FALSE(u == p.pose);
  }
  EXPECT_EQ(Poses(ChooseRound(input, model, cost)), Poses(again));  // deterministic
}

TEST(RoundChooserTest, RespectsEveryBudget) {
  const std::vector<Pose> candidates = Candidates();
  const RoundCost cost(Policies(), plan::RigDescription{});
  const KernelModel model = Peaked();
  const Pose at{0, 10, 0, 0};
  // Readings: 5 left of 105.
  Round r = ChooseRound({{}, candidates, at, {100, 0, 0}, {105, 0, 0}}, model, cost);
  EXPECT_EQ(r.poses.size(), 5u);
  // Rig time: 60 s left.
  r = ChooseRound({{}, candidates, at, {10, 540, 4}, {0, 600, 0}}, model, cost);
  ASSERT_FALSE(r.poses.empty());
  EXPECT_LE(r.cost.seconds, 60 + 1e-9);
  EXPECT_EQ(r.cost.seconds, cost.Sequence(at, Poses(r)).seconds);
  // Prompts: none left, so the detector stays where it is.
  r = ChooseRound({{}, candidates, at, {10, 0, 8}, {0, 0, 8}}, model, cost);
  ASSERT_FALSE(r.poses.empty());
  EXPECT_EQ(r.cost.prompts, 0);
  for (const ChosenPose& p : r.poses) EXPECT_EQ(p.pose.delta, at.delta);
  // Nothing affordable: an empty round, and the stop rule names the budget that is spent, though
  // 0.1 s of it is left.
  r = ChooseRound({{}, candidates, at, {10, 599.9, 0}, {0, 600, 0}}, model, cost);
  EXPECT_TRUE(r.poses.empty());
  EXPECT_EQ(AfterChoosing(r), StopReason::kTimeBudget);
  r = ChooseRound({{}, candidates, at, {10, 0, 8}, {0, 0, 8}}, model, cost);
  EXPECT_EQ(r.limited_by, StopReason::kPromptBudget);  // other detector positions were left out
  // Nothing predicted to gain, whatever the budget: the uncertainty, not the budget, stops it.
  const KernelModel settled([](const IsoDirection&) { return 0.0; });
  r = ChooseRound({{}, candidates, at, {10, 0, 0}, {1000, 0, 0}}, settled, cost);
  EXPECT_TRUE(r.poses.empty());
  EXPECT_EQ(AfterChoosing(r), StopReason::kNothingToGain);
}

TEST(RoundChooserTest, GroupingByDeltaSparesTheOperator) {
  const std::vector<Pose> candidates = Candidates();
  const RoundCost cost(Policies(), plan::RigDescription{});
  const KernelModel model = Uniform();
  const RoundInput input{{}, candidates, {0, 10, 0, 0}, {}, {1000, 0, 0}};
  const Round grouped = ChooseRound(input, model, cost, {.max_readings = 30});
  const Round ungrouped =
      ChooseRound(input, model, cost, {.max_readings = 30, .group_by_delta = false});
  ASSERT_EQ(grouped.poses.size(), 30u);
  ASSERT_EQ(ungrouped.poses.size(), 30u);
  EXPECT_LT(Prompts(grouped), Prompts(ungrouped));
  EXPECT_LT(grouped.cost.seconds, ungrouped.cost.seconds);
  // Grouped: each δ appears as one run.
  std::vector<double> runs;
  for (const ChosenPose& p : grouped.poses) {
    if (runs.empty() || runs.back() != p.pose.delta) runs.push_back(p.pose.delta);
  }
  std::set<double> distinct(runs.begin(), runs.end());
  EXPECT_EQ(runs.size(), distinct.size());
}

std::set<double> DeltasOf(const Round& round) {
  std::set<double> out;
  for (const ChosenPose& p : round.poses) out.insert(p.pose.delta);
  return out;
}

TEST(RoundChooserTest, ARoundRelocatesTheOperatorAtMostOnce) {
  // A manual detector with a reference per position: each δ change is prompts and a reference.
  const std::vector<Pose> candidates = Candidates();
  const RoundCost cost(Policies(), plan::RigDescription{});
  ASSERT_GT(cost.delta_change().prompts, 0);
  const KernelModel model = Uniform();
  const Pose at{0, 10, 0, 0};
  const RoundInput input{{}, candidates, at, {}, {1000, 0, 0}};
  const Round once = ChooseRound(input, model, cost, {.max_readings = 200});
  const Round any = ChooseRound(input, model, cost, {.max_readings = 200, .max_relocations = -1});
  ASSERT_FALSE(once.poses.empty());
  std::set<double> deltas = DeltasOf(once);
  deltas.erase(at.delta);
  EXPECT_LE(deltas.size(), 1u);
  EXPECT_LE(once.cost.prompts, cost.delta_change().prompts);
  EXPECT_GT(DeltasOf(any).size(), 2u);  // the limit is what kept it to one relocation
  EXPECT_GT(any.cost.prompts, once.cost.prompts);
  // Where a δ change is no prompt (a motorized arm, references not per position) the limit
  // does not apply.
  v1::Plan by_time;
  by_time.mutable_reference()->set_per_detector_position(false);
  plan::RigDescription arm;
  arm.has_detector_arm = true;
  const RoundCost arm_cost(by_time, arm);
  ASSERT_EQ(arm_cost.delta_change().prompts, 0);
  const Round free = ChooseRound(input, model, arm_cost, {.max_readings = 60});
  EXPECT_EQ(Poses(free), Poses(ChooseRound(input, model, arm_cost,
                                           {.max_readings = 60, .max_relocations = -1})));
}

TEST(RoundChooserTest, PosesGatherWhereTheUncertaintyIs) {
  // A motorized arm and no reference per position: where the poses go is the model's doing, not
  // the relocations' cost (GroupingByDeltaSparesTheOperator covers those).
  v1::Plan policies;
  policies.mutable_reference()->set_per_detector_position(false);
  plan::RigDescription arm;
  arm.has_detector_arm = true;
  const RoundCost cost(policies, arm);
  const std::vector<Pose> candidates = CandidatePoses(Spec(), arm, 5);
  const KernelModel model(
      [](const IsoDirection& d) {
        return 0.02 + std::exp(-IsoDistanceSquared(d, kPeak) / (2 * 12 * 12));
      },
      /*sigma=*/8, /*share=*/0.5);
  const Round round = ChooseRound({{}, candidates, {0, 10, 0, 0}, {}, {1000, 0, 0}}, model, cost,
                                  {.max_readings = 20});
  ASSERT_EQ(round.poses.size(), 20u);
  auto near = [](const Pose& p) {
    return IsoDistanceSquared(ToIsotropic(PoseToDirections(p)), kPeak) < 25 * 25;
  };
  const double chosen_near = std::count_if(round.poses.begin(), round.poses.end(),
                                           [&](const ChosenPose& c) { return near(c.pose); }) /
                             20.0;
  const double candidates_near = std::count_if(candidates.begin(), candidates.end(), near) /
                                 static_cast<double>(candidates.size());
  EXPECT_GE(chosen_near, 0.7);
  EXPECT_LT(candidates_near, 0.1);
  EXPECT_GT(round.predicted_gain, 0);
}

TEST(RoundChooserTest, RemainingUncertaintyFallsRoundByRoundToTheTarget) {
  const std::vector<Pose> candidates = Candidates();
  const RoundCost cost(Policies(), plan::RigDescription{});
  const KernelModel model = Peaked();
  const Target target{TargetKind::kExpandedUncertainty, 0.03};
  const Budget budget{400, 0, 0};
  std::vector<ReadingSoFar> readings;
  Spend spent;
  Pose at{0, 10, 0, 0};
  double previous = model.Map(readings)->Remaining();
  ASSERT_GT(previous, target.level);  // there is something to do
  StopReason reason = StopReason::kContinue;
  int rounds = 0;
  for (int round_no = 0; round_no < 30; ++round_no) {
    reason = ShouldStop(model.Map(readings)->Remaining(), target, budget, spent);
    if (reason != StopReason::kContinue) break;
    const Round round = ChooseRound({readings, candidates, at, spent, budget}, model, cost);
    reason = AfterChoosing(round);
    if (reason != StopReason::kContinue) break;
    for (const ChosenPose& p : round.poses) {
      readings.push_back({p.pose, PoseToDirections(p.pose), 0.1, 0.01});
      at = p.pose;
    }
    spent.readings += static_cast<int>(round.poses.size());
    spent.seconds += round.cost.seconds;
    spent.prompts += round.cost.prompts;
    const double now = model.Map(readings)->Remaining();
    EXPECT_LT(now, previous) << "round " << round_no;
    previous = now;
    ++rounds;
  }
  EXPECT_GE(rounds, 1);
  EXPECT_EQ(reason, StopReason::kTargetReached) << StopReasonText(reason);
  EXPECT_LE(spent.readings, 400);
}

TEST(StopRuleTest, TargetFirstThenEachBudget) {
  const Target target{TargetKind::kExpectedError, 0.05};
  EXPECT_EQ(ShouldStop(0.05, target, {10, 0, 0}, {10, 0, 0}), StopReason::kTargetReached);
  EXPECT_EQ(ShouldStop(0.2, target, {10, 0, 0}, {10, 0, 0}), StopReason::kReadingBudget);
  EXPECT_EQ(ShouldStop(0.2, target, {0, 600, 0}, {10, 600, 0}), StopReason::kTimeBudget);
  EXPECT_EQ(ShouldStop(0.2, target, {0, 0, 5}, {10, 0, 5}), StopReason::kPromptBudget);
  EXPECT_EQ(ShouldStop(0.2, target, {11, 601, 6}, {10, 600, 5}), StopReason::kContinue);
}

TEST(RoundCostTest, ADeltaChangeCostsItsPromptsByThePlansPolicies) {
  const Pose a{0, 30, 0, 0};
  const Pose b{0, 30, 0, 22.5};
  // Manual detector, a reference per position: relocate, mount white, mount sample.
  EXPECT_EQ(RoundCost(Policies(), plan::RigDescription{}).Step(a, b).prompts, 3);
  v1::Plan dark = Policies();
  dark.mutable_dark()->set_with_each_reference(true);
  EXPECT_EQ(RoundCost(dark, plan::RigDescription{}).Step(a, b).prompts, 4);
  // A motorized arm and no reference per position: no prompt at all.
  v1::Plan none = Policies();
  none.mutable_reference()->set_per_detector_position(false);
  plan::RigDescription arm;
  arm.has_detector_arm = true;
  EXPECT_EQ(RoundCost(none, arm).Step(a, b).prompts, 0);
  // Staying at δ: the move and the reading only.
  const RoundCost cost(Policies(), plan::RigDescription{});
  EXPECT_EQ(cost.Step(a, Pose{10, 30, 0, 0}).prompts, 0);
  EXPECT_GT(cost.Step(a, b).seconds, cost.Step(a, Pose{0, 30, 0, 0}).seconds + 3 * 30 - 1e-9);
}

TEST(CandidatesTest, EveryCandidateIsReachableAndInTheRegion) {
  const AdaptiveSpec spec = Spec();
  plan::RigDescription rig;
  rig.alpha = {0, 60, 10};
  const std::vector<Pose> candidates = CandidatePoses(spec, rig, 10);
  ASSERT_FALSE(candidates.empty());
  std::set<double> deltas;
  for (const Pose& p : candidates) {
    const Directions d = PoseToDirections(p);
    EXPECT_LE(d.theta_i, 75 + 1e-9);
    EXPECT_LE(d.theta_o, 75 + 1e-9);
    EXPECT_LE(p.alpha, 60);
    deltas.insert(p.delta);
  }
  EXPECT_EQ(deltas.size(), spec.delta_deg.size());
}

}  // namespace
}  // namespace brdf::adaptive
