// The entry points of core/plan: validate a plan against a rig, expand it into steps, and
// summarise it. Pure (no I/O); deterministic (the same plan and rig give the same steps, texts
// included).
//
// Step order. Every plan starts, before its first sample reading, with a white reference; a
// reference block is: prompt MOUNT_WHITE, MOVE to the reference pose (not for sample-fixed
// plans, whose references are taken where lamp and detector stand), REFERENCE, and when
// dark.withEachReference: prompt CLOSE_SHUTTER, DARK; then prompt MOUNT_SAMPLE. Later blocks come
// right before the sample reading (and its move) for which one of the reference policy's rules
// fires: after a detector relocation (perDetectorPosition), after everyNReadings sample
// readings, or once everyMinutes have passed by the timing estimate since the last reference.
//
//   sample rotation: for each detector position δ (a RELOCATE_DETECTOR prompt, or a MOVE of the δ
//     axis on a motorized arm), for each α, β in serpentine order (ascending on even rows,
//     descending on odd rows, counting rows across the whole plan): MOVE, SAMPLE. With several γ
//     values: on a manual dial γ is outermost (a SET_GAMMA_DIAL prompt per value, δ inside it);
//     on a motorized γ axis δ stays outermost and γ rides on the moves.
//   sample fixed: for each target: prompt RELOCATE_LAMP_AND_DETECTOR (its text gives the
//     angles), SAMPLE. No moves: the pose of these steps is the equivalent pose by inverse
//     kinematics.
//   pose list: for each pose: a dial prompt when a manual γ changes, a detector relocation when
//     δ changes (and before the first pose), MOVE, SAMPLE.
//   adaptive: the seed design (core/adaptive/seed_design.h) expanded as the pose list it is; the
//     rounds are chosen from the readings as the session goes (docs/adaptive.md), so they are not
//     among these steps, and the summary is the seed's cost. The seed must fit the plan's budget.
//     In the sample-fixed form (Adaptive.sample_fixed, core/adaptive/sample_fixed_design.h) each
//     seed pose is expanded as a sample-fixed target is: prompt RELOCATE_LAMP_AND_DETECTOR (its
//     text gives θi, θo and φ), SAMPLE; no moves, references where lamp and detector stand.
#pragma once

#include <vector>

#include "brdf/v1/plan.pb.h"
#include "core/plan/plan_summary.h"
#include "core/plan/problem.h"
#include "core/plan/rig_description.h"
#include "core/plan/step.h"
#include "core/status.h"

namespace brdf::plan {

struct PlanAnalysis {
  // Every problem found; empty when the plan is valid for the rig.
  std::vector<Problem> problems;
  // The expanded plan; empty when there are problems.
  std::vector<Step> steps;
  // Summary of `steps` (all zero when there are problems).
  PlanSummary summary;
  bool valid() const { return problems.empty(); }
};

// Checks, expands and summarises in one pass.
// Checks: ranges (NaN, infinities, zero or negative steps, stop < start, θ beyond 90°, δ beyond
// 180°), required fields, the stage's travel limits (α and δ sweeps, every β of the grid, γ on a
// motorized axis, reference poses, explicit poses), reachability (sample-fixed targets by
// inverse kinematics; explicit poses with lamp and detector above the surface), reference poses
// within kReferenceThetaMaxDeg of the white's normal, meter and retry settings, and the cap of
// kMaxSteps steps. Every problem is reported, each with its JSON field path (problem.h).
// The steps are expanded as the daemon runs them (the "every M minutes" reference rule by
// `rig`'s own timing); the summary's times are for the rig's devices running `time_scale` times
// faster (a simulated rig, timing.h), which changes no step.
PlanAnalysis AnalyzePlan(const v1::Plan& plan, const RigDescription& rig, double time_scale = 1);

// AnalyzePlan's problems.
std::vector<Problem> ValidatePlan(const v1::Plan& plan, const RigDescription& rig);

// AnalyzePlan's steps; kInvalidArgument listing every problem ("path: message" lines) when the
// plan is not valid for the rig.
Result<std::vector<Step>> ExpandPlan(const v1::Plan& plan, const RigDescription& rig);

}  // namespace brdf::plan
