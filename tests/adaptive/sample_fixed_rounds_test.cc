// The sample-fixed method's form of adaptive plans (sample_fixed_design.h, prompt_order.h,
// round_steps.h): every pose is a prompt, so the prompt budget limits the session and each
// round's prompts are ordered to keep the operator's carries of lamp and detector short. A
// session is run here as the engine runs it (seed, then rounds chosen from the readings so far
// and expanded after the stored steps) on the stand-in model.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <tuple>
#include <vector>

#include "core/adaptive/prompt_order.h"
#include "core/adaptive/refine_candidates.h"
#include "core/adaptive/round_chooser.h"
#include "core/adaptive/round_cost.h"
#include "core/adaptive/round_steps.h"
#include "core/adaptive/sample_fixed_design.h"
#include "core/adaptive/stop_rule.h"
#include "core/geometry.h"
#include "core/plan/analyze_plan.h"
#include "core/plan/expand_steps.h"
#include "kernel_model.h"

namespace brdf::adaptive {
namespace {

using testing::IsoDistanceSquared;
using testing::KernelModel;

KernelModel Peaked() {
  return KernelModel([](const IsoDirection& d) {
    return 0.05 + std::exp(-IsoDistanceSquared(d, {30, 30, 180}) / (2 * 12 * 12));
  });
}

// A sample-fixed adaptive plan over θ ≤ 60°: 4 retro-reflection and 8 space-filling seed poses,
// rounds of 8, at most `max_prompts` prompts; references at the start and then every
// `reference_every` readings (0: never again).
v1::Plan FixedPlan(int max_prompts, int reference_every = 0) {
  v1::Plan plan;
  v1::Adaptive* a = plan.mutable_adaptive();
  a->mutable_target()->set_expanded_uncertainty(0.001);
  a->mutable_budget()->set_max_prompts(static_cast<std::uint32_t>(max_prompts));
  a->mutable_region()->set_theta_i_max_deg(60);
  a->mutable_region()->set_theta_o_max_deg(60);
  a->mutable_seed()->set_retro_readings(4);
  a->mutable_sample_fixed()->set_seed_readings(8);
  a->set_round_readings(8);
  plan.mutable_reference()->set_per_detector_position(false);
  plan.mutable_reference()->set_every_n_readings(static_cast<std::uint32_t>(reference_every));
  return plan;
}

std::vector<Pose> Poses(const Round& round) {
  std::vector<Pose> out;
  for (const ChosenPose& c : round.poses) out.push_back(c.pose);
  return out;
}

struct Session {
  std::vector<plan::Step> steps;
  std::vector<std::vector<Pose>> picked;    // each round in the chooser's order
  std::vector<std::vector<Pose>> measured;  // each round as stored (prompt order)
  std::vector<Pose> from;                   // where lamp and detector stood before each round
  StopReason stop = StopReason::kContinue;
};

// The seed, then rounds as the engine chooses and stores them (daemon/engine/adaptive_rounds).
Session RunSession(const v1::Plan& plan, const UncertaintyModel& model) {
  const plan::RigDescription rig;
  Session s;
  Result<std::vector<plan::Step>> seed = plan::ExpandPlan(plan, rig);
  EXPECT_TRUE(seed.ok()) << seed.status().ToString();
  if (!seed.ok()) return s;
  s.steps = *seed;
  const AdaptiveSpec spec = ResolveAdaptive(plan.adaptive());
  const std::vector<Pose> candidates = FixedCandidates(spec);
  const RoundCost cost(plan, rig);
  for (int r = 0; r < 100 && s.stop == StopReason::kContinue; ++r) {
    std::vector<ReadingSoFar> readings;
    for (const plan::Step& st : s.steps) {
      if (st.kind != v1::STEP_KIND_SAMPLE) continue;
      readings.push_back({ToModelAngles(st.pose, rig.convention), *st.target, 0.1, 0.02});
    }
    const Spend spent = SpendOfSteps(s.steps, plan, rig);
    const std::unique_ptr<UncertaintyMap> map = model.Map(readings);
    s.stop = ShouldStop(map->Remaining(), spec.target, spec.budget, spent);
    if (s.stop != StopReason::kContinue) break;
    const plan::ExpansionStart start = plan::StartAfter(s.steps, plan, rig);
    const RoundInput input{readings, candidates, start.model, spent, spec.budget};
    Round round = ChooseRound(input, *map, cost, {.max_readings = spec.round_readings});
    const std::vector<Pose> picked = Poses(round);
    const std::vector<plan::Step> added =
        RoundSteps(plan, rig, s.steps, spent, start, spec.budget, round);
    s.stop = AfterChoosing(round);
    if (s.stop != StopReason::kContinue) break;
    s.picked.push_back(picked);
    s.measured.push_back(Poses(round));
    s.from.push_back(start.model);
    s.steps.insert(s.steps.end(), added.begin(), added.end());
  }
  return s;
}

int CountPrompts(const std::vector<plan::Step>& steps, v1::PromptKind kind) {
  return static_cast<int>(std::count_if(steps.begin(), steps.end(), [&](const plan::Step& s) {
    return s.kind == v1::STEP_KIND_PROMPT && s.prompt == kind;
  }));
}

TEST(SampleFixedRoundsTest, CandidatesAreDirectionPairsInTheRegion) {
  AdaptiveSpec spec;
  spec.sample_fixed = true;
  spec.region = {10, 60, 0, 70};
  const std::vector<Pose> candidates = FixedCandidates(spec);
  // θi 10 … 60 (11 values) × θo 0 … 70 (15): 14 of θo with 19 φ each, and θo = 0 with one.
  EXPECT_EQ(candidates.size(), 11u * (14u * 19u + 1u));
  for (const Pose& c : candidates) {
    const IsoDirection d = FixedTarget(c);
    EXPECT_TRUE(RegionContains(spec.region, CanonicalDirections(d)));
    EXPECT_NEAR(d.theta_i, std::round(d.theta_i), 1e-6);
    EXPECT_NEAR(d.phi, std::round(d.phi / 10) * 10, 1e-6);
  }
}

TEST(SampleFixedRoundsTest, EveryPoseCostsItsPromptAndWhatThePoliciesAdd) {
  const plan::RigDescription rig;
  v1::Plan plan = FixedPlan(100);
  const PoseCost by_time = FixedPoseCost(plan, rig);
  EXPECT_EQ(by_time.prompts, 1);
  EXPECT_GT(by_time.seconds, rig.operator_action_s);
  // The chooser's cost is the same wherever the pose goes.
  const RoundCost cost(plan, rig);
  const Pose a = *FixedPose({10, 20, 30});
  const Pose b = *FixedPose({60, 50, 170});
  EXPECT_EQ(cost.Step(a, b).prompts, 1);
  EXPECT_DOUBLE_EQ(cost.Step(a, b).seconds, by_time.seconds);
  EXPECT_DOUBLE_EQ(cost.Step(a, a).seconds, by_time.seconds);
  // A reference at every target: the white and the sample mounted by hand as well.
  plan.mutable_reference()->set_per_detector_position(true);
  const PoseCost per_target = FixedPoseCost(plan, rig);
  EXPECT_EQ(per_target.prompts, 3);
  EXPECT_GT(per_target.seconds, by_time.seconds + 2 * rig.operator_action_s);
}

TEST(SampleFixedRoundsTest, PromptOrderShortensTheCarriesAndKeepsThePoses) {
  const Pose from = *FixedPose({0, 0, 0});
  std::vector<Pose> poses;
  for (const IsoDirection& d : std::vector<IsoDirection>{
           {40, 40, 180}, {10, 10, 90}, {30, 30, 180}, {20, 20, 90}, {50, 10, 0}}) {
    poses.push_back(*FixedPose(d));
  }
  const std::vector<Pose> ordered = OrderForPrompts(from, poses);
  EXPECT_LT(PromptTravel(from, ordered), PromptTravel(from, poses));
  EXPECT_TRUE(std::is_permutation(ordered.begin(), ordered.end(), poses.begin()));
  EXPECT_EQ(OrderForPrompts(from, poses), ordered);
  // Along one line, from one end: in order.
  std::vector<Pose> line;
  for (double t : {40.0, 10.0, 30.0, 20.0}) line.push_back(*FixedPose({t, t, 180}));
  const std::vector<Pose> walk = OrderForPrompts(from, line);
  ASSERT_EQ(walk.size(), 4u);
  for (std::size_t i = 0; i < walk.size(); ++i) {
    EXPECT_NEAR(FixedTarget(walk[i]).theta_i, 10.0 * static_cast<double>(i + 1), 1e-6);
  }
  // An order already shortest is kept as given.
  EXPECT_EQ(OrderForPrompts(walk.front(), walk), walk);
}

TEST(SampleFixedRoundsTest, ASessionNeverPassesThePromptBudgetAndOrdersItsPrompts) {
  const v1::Plan plan = FixedPlan(50);
  const Session s = RunSession(plan, Peaked());
  ASSERT_GE(s.measured.size(), 3u);
  EXPECT_EQ(s.stop, StopReason::kPromptBudget) << StopReasonText(s.stop);
  const Spend spent = SpendOfSteps(s.steps, plan, plan::RigDescription{});
  EXPECT_LE(spent.prompts, 50);
  EXPECT_GE(spent.prompts, 49);  // stopped because no further pose fits
  // Every pose a prompt; the holder never moves.
  EXPECT_EQ(CountPrompts(s.steps, v1::PROMPT_KIND_RELOCATE_LAMP_AND_DETECTOR), spent.readings);
  EXPECT_TRUE(std::none_of(s.steps.begin(), s.steps.end(),
                           [](const plan::Step& st) { return st.kind == v1::STEP_KIND_MOVE; }));
  double ordered = 0;
  double as_picked = 0;
  for (std::size_t r = 0; r < s.measured.size(); ++r) {
    EXPECT_LE(s.measured[r].size(), 8u);
    ASSERT_TRUE(std::is_permutation(s.measured[r].begin(), s.measured[r].end(), s.picked[r].begin(),
                                    s.picked[r].end()))
        << "round " << r;
    const double travel = PromptTravel(s.from[r], s.measured[r]);
    const double picked = PromptTravel(s.from[r], s.picked[r]);
    EXPECT_LE(travel, picked + 1e-9) << "round " << r;
    ordered += travel;
    as_picked += picked;
  }
  EXPECT_LT(ordered, 0.9 * as_picked);
}

TEST(SampleFixedRoundsTest, ReferencesByCountAreInsideThePromptBudget) {
  // A reference every 3 readings adds two prompts that the chooser's per-pose cost leaves out:
  // the round's steps are cut to the budget all the same.
  const v1::Plan plan = FixedPlan(45, 3);
  const Session s = RunSession(plan, Peaked());
  ASSERT_FALSE(s.measured.empty());
  const Spend spent = SpendOfSteps(s.steps, plan, plan::RigDescription{});
  EXPECT_LE(spent.prompts, 45);
  EXPECT_GT(CountPrompts(s.steps, v1::PROMPT_KIND_MOUNT_WHITE), spent.readings / 3 - 1);
  EXPECT_EQ(s.stop, StopReason::kPromptBudget) << StopReasonText(s.stop);
}

TEST(SampleFixedRoundsTest, SameReadingsGiveTheSameSession) {
  const v1::Plan plan = FixedPlan(40);
  const Session a = RunSession(plan, Peaked());
  const Session b = RunSession(plan, Peaked());
  ASSERT_FALSE(a.measured.empty());
  EXPECT_EQ(a.measured, b.measured);
  ASSERT_EQ(a.steps.size(), b.steps.size());
  for (std::size_t i = 0; i < a.steps.size(); ++i) {
    EXPECT_EQ(a.steps[i].prompt_text, b.steps[i].prompt_text);
  }
}

// The operator sets whole degrees by hand: no finer candidates in this form, whoever chooses
// (the round chooser's default options refine), so every pick is one of the plan's candidates.
TEST(SampleFixedRoundsTest, NoFinerCandidatesBetweenTheHandSetPoses) {
  const v1::Plan plan = FixedPlan(50);
  const plan::RigDescription rig;
  const AdaptiveSpec spec = ResolveAdaptive(plan.adaptive());
  const std::vector<Pose> candidates = FixedCandidates(spec);
  std::vector<ReadingSoFar> readings;  // every 40th candidate
  for (std::size_t i = 0; i < candidates.size(); i += 40) {
    readings.push_back({candidates[i], PoseToDirections(candidates[i]), 0.1, 0.02});
  }
  const RoundCost cost(plan, rig);
  EXPECT_TRUE(cost.sample_fixed());
  const KernelModel model = Peaked();
  const auto map = model.Map(readings);
  EXPECT_TRUE(RefinedCandidates(readings, candidates, *map, cost).empty());
  const Round round =
      ChooseRound({readings, candidates, readings.back().pose, {}, spec.budget}, *map, cost, {});
  ASSERT_FALSE(round.poses.empty());
  for (const ChosenPose& c : round.poses) {
    EXPECT_TRUE(std::find(candidates.begin(), candidates.end(), c.pose) != candidates.end());
  }
  // The rotation form's cost refines: the same plan without sampleFixed.
  v1::Plan rotation = plan;
  rotation.mutable_adaptive()->clear_sample_fixed();
  EXPECT_FALSE(RoundCost(rotation, rig).sample_fixed());
}

TEST(SampleFixedRoundsTest, RoundsGoWhereTheUncertaintyIs) {
  const Session s = RunSession(FixedPlan(50), Peaked());
  ASSERT_FALSE(s.measured.empty());
  int near = 0;
  for (const Pose& p : s.measured.front()) {
    near += IsoDistanceSquared(FixedTarget(p), {30, 30, 180}) < 25 * 25;
  }
  EXPECT_GE(near, 4);
}

}  // namespace
}  // namespace brdf::adaptive
