// The physical lower bound of core/plan/timing.h on hand-made step lists: what overlaps with
// pipelining (a move after a reading hides behind its transfer), what a sequential executor
// cannot hide, and the meter's own measuring time.
#include <gtest/gtest.h>

#include <algorithm>
#include <vector>

#include "core/plan/timing.h"
#include "tests/plan/plan_test_util.h"

namespace brdf::plan {
namespace {

Step Move(double alpha, double beta) {
  return testing::MoveTo(alpha, beta);
}
Step Sample() {
  return testing::StepOfKind(v1::STEP_KIND_SAMPLE);
}

RigDescription Rig() {
  RigDescription rig;
  rig.alpha.speed_deg_s = 10;
  rig.beta.speed_deg_s = 20;
  rig.meter_transfer_s = 1.8;
  rig.meter_measure_overhead_s = 1.0;
  return rig;
}

MeasurementChoice Fixed(int integration_ms, int averages) {
  MeasurementChoice m;
  m.integration_ms = static_cast<std::uint32_t>(integration_ms);
  m.averages = static_cast<std::uint32_t>(averages);
  return m;
}

TEST(TimingBoundTest, MovesAfterAReadingHideBehindItsTransferOnlyWhenPipelined) {
  const RigDescription rig = Rig();
  const MeasurementChoice m = Fixed(200, 2);
  // move 30° of β (1.5 s), sample, move 60° of β (3 s), sample, move 10° of α (1 s), sample.
  const std::vector<Step> steps = {Move(0, 30), Sample(),     Move(0, 90),
                                   Sample(),    Move(10, 90), Sample()};
  const double reading = 0.2 * 2 + rig.meter_measure_overhead_s + rig.meter_transfer_s;
  const double first_move = 30 / rig.beta.speed_deg_s;  // from pose 0: nothing to hide behind
  const double second = 60 / rig.beta.speed_deg_s;
  const double third = 10 / rig.alpha.speed_deg_s;

  const double pipelined = PlanLowerBound(steps, rig, m, true);
  EXPECT_NEAR(pipelined,
              first_move + 3 * reading + std::max(0.0, second - rig.meter_transfer_s) +
                  std::max(0.0, third - rig.meter_transfer_s),
              1e-9);
  const double sequential = PlanLowerBound(steps, rig, m, false);
  EXPECT_NEAR(sequential, first_move + 3 * reading + second + third, 1e-9);
  // The pipelined bound is StepTimer's sum, the one the plan summary reports.
  double sum = 0;
  for (const StepTime& t : EstimateSteps(steps, rig, m)) sum += t.lower_bound_s;
  EXPECT_NEAR(pipelined, sum, 1e-9);
}

TEST(TimingBoundTest, TheMetersOwnMeasuringTimeCountsOncePerReading) {
  RigDescription rig = Rig();
  const std::vector<Step> steps = {Sample(), Sample(), Sample()};
  const double with = PlanLowerBound(steps, rig, Fixed(100, 1));
  rig.meter_measure_overhead_s = 0;
  const double without = PlanLowerBound(steps, rig, Fixed(100, 1));
  EXPECT_NEAR(with - without, 3 * Rig().meter_measure_overhead_s, 1e-9);
}

}  // namespace
}  // namespace brdf::plan
