// Field-by-field checks of a plan that need no expansion: numbers finite and in range, required
// fields present, sweeps that end where they start, targets that inverse kinematics can reach,
// explicit poses within the stage's travel, and counts small enough to expand. Part of
// ValidatePlan (core/plan/analyze_plan.h); the checks that need the expanded steps (β travel,
// reference poses, the step cap) run during expansion (core/plan/expand_steps.h).
#pragma once

#include <cstddef>

#include "brdf/v1/plan.pb.h"
#include "core/plan/problem.h"
#include "core/plan/rig_description.h"
#include "core/pose.h"
#include "core/status.h"

namespace brdf::plan {

// Limits of what a plan may ask for (besides kMaxSteps).
inline constexpr int kMaxSweepValues = 100000;         // values of one angle sweep
inline constexpr double kMaxGridCandidates = 1000000;  // δ × α × β × γ combinations examined
inline constexpr std::size_t kMaxNameLength = 256;     // Plan.name, in bytes

// Adds every problem found to `sink`, in field order.
void CheckPlanFields(const v1::Plan& plan, const RigDescription& rig, ProblemSink& sink);

// Inverse kinematics for a sample-fixed target: the equivalent pose in model angles (γ set so
// that a four-angle target's azimuths match too). Errors name the unreachable direction.
Result<Pose> SolveTargetPose(const v1::DirectionTarget& target);

}  // namespace brdf::plan
