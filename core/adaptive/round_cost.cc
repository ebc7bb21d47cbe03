#include "core/adaptive/round_cost.h"

#include <cstddef>
#include <vector>

#include "core/adaptive/sample_fixed_design.h"
#include "core/adaptive/seed_design.h"
#include "core/geometry.h"
#include "core/plan/expand_steps.h"
#include "core/plan/problem.h"
#include "core/plan/timing.h"

namespace brdf::adaptive {
namespace {

plan::Step StepAt(plan::StepKind kind, const Pose& model, const plan::RigDescription& rig) {
  plan::Step step;
  step.kind = kind;
  step.pose = ToReadings(model, rig.convention);
  return step;
}

void AddPose(v1::PoseList& list, double beta, double delta) {
  v1::PoseEntry* e = list.add_poses();
  e->set_alpha(0);
  e->set_beta(beta);
  e->set_delta(delta);
}

// What the plan expander puts between a reading at δ = 0 and the next one at another δ.
PoseCost MeasureDeltaChange(const v1::Plan& plan, const plan::RigDescription& rig) {
  v1::Plan probe = plan;
  probe.clear_method();
  v1::PoseList* list = probe.mutable_pose_list();
  const double delta = GridSpec{}.delta_step_deg;
  AddPose(*list, 30, 0);
  AddPose(*list, 30, delta);
  // Between the first reading and the move to the second pose (that move is Step()'s).
  return CostAfterFirstReading(probe, plan, rig, false);
}

}  // namespace

PoseCost CostAfterFirstReading(const v1::Plan& probe, const v1::Plan& plan,
                               const plan::RigDescription& rig, bool through_second) {
  plan::ProblemSink ignored;
  const std::vector<plan::Step> steps = plan::ExpandCheckedPlan(probe, rig, ignored);
  const std::vector<plan::StepTime> times =
      plan::EstimateSteps(steps, rig, plan::ResolveSettings(plan).measurement);
  std::vector<std::size_t> samples;
  for (std::size_t i = 0; i < steps.size(); ++i) {
    if (steps[i].kind == v1::STEP_KIND_SAMPLE) samples.push_back(i);
  }
  PoseCost cost;
  if (samples.size() != 2) return cost;
  const std::size_t end = through_second ? samples[1] + 1 : samples[1] - 1;
  for (std::size_t i = samples[0] + 1; i < end; ++i) {
    cost.seconds += times[i].estimate_s;
    if (steps[i].kind == v1::STEP_KIND_PROMPT) ++cost.prompts;
  }
  return cost;
}

RoundCost::RoundCost(const v1::Plan& plan, const plan::RigDescription& rig)
    : rig_(rig),
      region_(ResolveAdaptive(plan.adaptive()).region),
      measurement_(plan::ResolveSettings(plan).measurement) {
  rig_.time_scale = 1;
  delta_change_ = MeasureDeltaChange(plan, rig_);
  if (plan::SampleFixedMethod(plan)) fixed_pose_ = FixedPoseCost(plan, rig_);
}

double RoundCost::MoveAndReadSeconds(const Pose& from, const Pose& to) const {
  if (fixed_pose_.has_value()) return fixed_pose_->seconds;
  plan::StepTimer timer(rig_, measurement_);
  timer.Advance(StepAt(v1::STEP_KIND_MOVE, from, rig_));
  timer.Advance(StepAt(v1::STEP_KIND_SAMPLE, from, rig_));
  const double before = timer.elapsed_estimate_s();
  timer.Advance(StepAt(v1::STEP_KIND_MOVE, to, rig_));
  timer.Advance(StepAt(v1::STEP_KIND_SAMPLE, to, rig_));
  return timer.elapsed_estimate_s() - before;
}

PoseCost RoundCost::Step(const Pose& from, const Pose& to) const {
  if (fixed_pose_.has_value()) return *fixed_pose_;
  PoseCost cost{MoveAndReadSeconds(from, to), 0};
  if (to.delta != from.delta) cost += delta_change_;
  if (to.gamma != from.gamma && !rig_.has_gamma_axis) cost += PoseCost{rig_.operator_action_s, 1};
  return cost;
}

bool RoundCost::CanReach(const Pose& pose) const {
  return Reachable(pose, region_, rig_);
}

PoseCost RoundCost::Sequence(const Pose& from, std::span<const Pose> poses) const {
  PoseCost total;
  Pose at = from;
  for (const Pose& p : poses) {
    total += Step(at, p);
    at = p;
  }
  return total;
}

}  // namespace brdf::adaptive
