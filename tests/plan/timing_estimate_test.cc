// The estimate of core/plan/timing.h for a rig whose devices run faster (brdf-sim --time-scale):
// the daemon's own waits (command pacing, quiet gaps, stage polling) and the operator's time do
// not shrink with the devices. Each test holds one of the causes found when validate's estimate
// for the paper grid at time scale 32 came out 21 % short of the simulated run.
#include <gtest/gtest.h>

#include <cmath>
#include <fstream>
#include <sstream>
#include <string>
#include <vector>

#include "core/plan/analyze_plan.h"
#include "core/plan/timing.h"
#include "tests/plan/plan_test_util.h"

namespace brdf::plan {
namespace {

using testing::MoveTo;
using testing::StepOfKind;

RigDescription Rig(double time_scale) {
  RigDescription rig;
  rig.alpha.speed_deg_s = 10;
  rig.beta.speed_deg_s = 20;
  rig.meter_transfer_s = 1.8;
  rig.reading_overhead_s = 0.3;
  rig.adaptive_integration = {.reference_s = 0.15, .dark_s = 6.0, .sample_s = 2.0};
  rig.move_settle_s = 0.25;
  rig.reading_host_s = 0.030;  // pacing_ms = 10, quiet_gap_ms = 20, M5
  rig.reading_host_after_s = 0.020;
  rig.stage_poll_s = 0.1;
  rig.operator_action_s = 30;
  rig.time_scale = time_scale;
  return rig;
}

MeasurementChoice Adaptive() {
  return MeasurementChoice{};
}

// Cause 1: a reading's host time (pacing, quiet gap) is added whole at any time scale.
TEST(TimingEstimateTest, AReadingsHostWaitsDoNotScaleWithTheRig) {
  const std::vector<Step> steps = {StepOfKind(v1::STEP_KIND_SAMPLE)};
  const double device = 0.3 + 2.0 + 1.8;
  for (double k : {1.0, 8.0, 32.0}) {
    const std::vector<StepTime> t = EstimateSteps(steps, Rig(k), Adaptive());
    ASSERT_EQ(t.size(), 1u);
    EXPECT_NEAR(t[0].estimate_s, device / k + 0.030, 1e-12) << "time scale " << k;
    // The lower bound is physics: all device time.
    EXPECT_NEAR(t[0].lower_bound_s, (0.010 + 1.8) / k, 1e-12) << "time scale " << k;
  }
}

// Cause 2: the stage driver sees a move end only at a poll, so a move takes a whole number of
// polls however fast the stage; after a reading it hides behind the scaled transfer and the
// reply's quiet gap, which at time scale 32 no longer covers a poll.
TEST(TimingEstimateTest, AMoveTakesWholeStagePollsAndHidesOnlyBehindTheScaledTransfer) {
  // β 5° at 20°/s: 0.25 s of motion + 0.25 s settling.
  const std::vector<Step> steps = {MoveTo(0, 5), StepOfKind(v1::STEP_KIND_SAMPLE), MoveTo(0, 10)};
  {
    const std::vector<StepTime> t = EstimateSteps(steps, Rig(1), Adaptive());
    EXPECT_NEAR(t[0].estimate_s, 0.5, 1e-12);  // five polls
    EXPECT_NEAR(t[2].estimate_s, 0.0, 1e-12);  // hidden behind the 1.8 s transfer
  }
  {
    const std::vector<StepTime> t = EstimateSteps(steps, Rig(32), Adaptive());
    EXPECT_NEAR(t[0].estimate_s, 0.1, 1e-12);  // 15.6 ms of motion: seen at the first poll
    EXPECT_NEAR(t[2].estimate_s, 0.1 - 1.8 / 32 - 0.020, 1e-12);
    EXPECT_NEAR(t[2].lower_bound_s, 0.0, 1e-12);  // 7.8 ms of motion under 56 ms of transfer
  }
  // Without polling (stage_poll_s = 0) the move is its motion and settling.
  RigDescription continuous = Rig(32);
  continuous.stage_poll_s = 0;
  EXPECT_NEAR(EstimateSteps(steps, continuous, Adaptive())[0].estimate_s, 0.5 / 32, 1e-12);
  // Nothing moving takes no time, polls or not.
  const std::vector<Step> still = {MoveTo(0, 0)};
  EXPECT_EQ(EstimateSteps(still, Rig(32), Adaptive())[0].estimate_s, 0.0);
}

// Cause 3: prompts are the operator's time, never divided by the rig's time scale; the summary
// at a time scale keeps the plan's steps (the "every M minutes" rule runs on the daemon's clock).
TEST(TimingEstimateTest, PromptsAndStepsDoNotChangeWithTheTimeScale) {
  const std::vector<Step> prompt = {StepOfKind(v1::STEP_KIND_PROMPT)};
  EXPECT_NEAR(EstimateSteps(prompt, Rig(32), Adaptive())[0].estimate_s, 30, 1e-12);

  std::ifstream in(std::string(BRDF_EXAMPLES_DIR) + "/demo.json");
  std::stringstream text;
  text << in.rdbuf();
  const v1::Plan plan = testing::PlanFromJson(text.str());
  RigDescription rig;
  rig.has_detector_arm = true;
  const PlanAnalysis real = AnalyzePlan(plan, rig);
  const PlanAnalysis fast = AnalyzePlan(plan, rig, 32);
  ASSERT_TRUE(real.valid());
  ASSERT_TRUE(fast.valid());
  EXPECT_EQ(fast.summary.step_count, real.summary.step_count);
  EXPECT_EQ(fast.summary.reference_readings, real.summary.reference_readings);
  const double prompts_s = real.summary.operator_interventions * rig.operator_action_s;
  // Faster devices, but by less than 32: the host waits stay.
  const double real_rig = real.summary.estimated_duration_s - prompts_s;
  const double fast_rig = fast.summary.estimated_duration_s - prompts_s;
  EXPECT_LT(fast_rig, real_rig / 8);
  EXPECT_GT(fast_rig, real_rig / 32);
  EXPECT_NEAR(fast.summary.physical_lower_bound_s, real.summary.physical_lower_bound_s / 32, 1e-9);
}

// Adaptive integration follows the light, so each kind of reading has its own expected time: a
// dark reading (nothing to fill the detector) runs to the meter's longest, a reference on the
// white standard is short. The meter's overhead is paid once per reading.
TEST(TimingEstimateTest, AdaptiveIntegrationIsPerKindAndOverheadIsPerReading) {
  const RigDescription rig = Rig(8);
  auto readings = [](int darks, int samples) {
    std::vector<Step> steps;
    for (int i = 0; i < darks; ++i) steps.push_back(StepOfKind(v1::STEP_KIND_DARK));
    for (int i = 0; i < samples; ++i) steps.push_back(StepOfKind(v1::STEP_KIND_SAMPLE));
    return steps;
  };
  auto total = [](const std::vector<StepTime>& times) {
    double sum = 0;
    for (const StepTime& t : times) sum += t.estimate_s;
    return sum;
  };
  const std::vector<Step> dark_heavy = readings(8, 2);
  const std::vector<Step> sample_heavy = readings(2, 8);
  const double dark_heavy_s = total(EstimateSteps(dark_heavy, rig, Adaptive()));
  const double sample_heavy_s = total(EstimateSteps(sample_heavy, rig, Adaptive()));
  // Same ten readings; six of them swap 2 s of sample integration for 6 s of dark.
  EXPECT_GT(dark_heavy_s, sample_heavy_s);
  EXPECT_NEAR(dark_heavy_s - sample_heavy_s, 6 * (6.0 - 2.0) / 8, 1e-12);

  // Each kind uses its own time: (overhead + integration + transfer) / k + host.
  const std::vector<Step> one_of_each = {StepOfKind(v1::STEP_KIND_REFERENCE),
                                         StepOfKind(v1::STEP_KIND_DARK),
                                         StepOfKind(v1::STEP_KIND_SAMPLE)};
  const std::vector<StepTime> each = EstimateSteps(one_of_each, rig, Adaptive());
  ASSERT_EQ(each.size(), 3u);
  EXPECT_NEAR(each[0].estimate_s, (0.3 + 0.15 + 1.8) / 8 + 0.030, 1e-12);
  EXPECT_NEAR(each[1].estimate_s, (0.3 + 6.0 + 1.8) / 8 + 0.030, 1e-12);
  EXPECT_NEAR(each[2].estimate_s, (0.3 + 2.0 + 1.8) / 8 + 0.030, 1e-12);
  // The lower bound still counts the meter's shortest integration, whatever the kind.
  for (const StepTime& t : each) EXPECT_NEAR(t.lower_bound_s, (0.010 + 1.8) / 8, 1e-12);

  // A fixed integration time overrides the per-kind times.
  MeasurementChoice fixed;
  fixed.integration_ms = 500;
  EXPECT_NEAR(total(EstimateSteps(dark_heavy, rig, fixed)),
              total(EstimateSteps(sample_heavy, rig, fixed)), 1e-12);

  // The overhead counts once per reading: 1 s more of it adds 10 s (÷ k) to ten readings, and
  // averaging (integration × averages) does not multiply it.
  RigDescription slower = rig;
  slower.reading_overhead_s += 1.0;
  EXPECT_NEAR(total(EstimateSteps(sample_heavy, slower, Adaptive())) - sample_heavy_s, 10 * 1.0 / 8,
              1e-12);
  MeasurementChoice averaged;
  averaged.averages = 4;
  const std::vector<StepTime> four = EstimateSteps(one_of_each, slower, averaged);
  EXPECT_NEAR(four[2].estimate_s, (1.3 + 4 * 2.0 + 1.8) / 8 + 0.030, 1e-12);
}

}  // namespace
}  // namespace brdf::plan
