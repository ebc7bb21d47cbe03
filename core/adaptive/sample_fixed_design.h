// The sample-fixed method's form of an adaptive plan (plan.proto: AdaptiveSampleFixed): the
// sample stays put and the operator places lamp and detector by hand at each pose's directions,
// a prompt per pose. Every pose is a direction pair (θi, θo, φ) within the region, carried
// through the planner as its equivalent pose (model angles, inverse kinematics with γ = 0, as a
// fixed sample-fixed plan records each target), so the round chooser, the uncertainty model and
// the stored rounds handle both forms alike. The holder never moves: the rig's travel limits do
// not apply. Isotropic samples only. Pure and deterministic.
//
// The seed: the retro-reflection scan (θi = θo evenly across the region, φ = 0, as
// seed_design.h's), then fixed_seed_readings space-filling direction pairs from the Halton
// sequence in bases 2, 3 and 5 — sin²θi and sin²θo uniform over the region's limits (an even
// spread in projected solid angle, the weight the target integrates with) and φ uniform over
// [0°, 180°] — rounded to whole degrees (the operator sets them by hand), repeats skipped;
// the space-filling poses ordered for the operator (prompt_order.h) from the scan's last pose.
//
// The candidates: θi and θo every kCandidateStepDeg from each limit's start (the limit itself
// included), φ every kFixedCandidatePhiStepDeg over [0°, 180°]; one φ only where θi or θo is 0
// (the azimuth is undefined on the normal).
#pragma once

#include <vector>

#include "brdf/v1/plan.pb.h"
#include "core/adaptive/adaptive_spec.h"
#include "core/adaptive/round_cost.h"
#include "core/adaptive/seed_design.h"
#include "core/plan/rig_description.h"
#include "core/pose.h"
#include "core/status.h"

namespace brdf::adaptive {

// The equivalent pose (model angles) of direction pair `target`; an error for a pair no pose
// reaches (a target outside [0°, 90°] × [0°, 90°] × [0°, 180°]).
Result<Pose> FixedPose(const IsoDirection& target);

// The direction pair a sample-fixed pose stands for, rounded to 1e-6° (the prompt's angles).
IsoDirection FixedTarget(const Pose& model);

// The seed design: one group (γ = 0, δ unused), the retro-reflection scan's poses first.
SeedGroup FixedSeedDesign(const AdaptiveSpec& spec);

// The candidate poses, in (θi, θo, φ) order.
std::vector<Pose> FixedCandidates(const AdaptiveSpec& spec);

// What one pose costs a sample-fixed plan under `plan`'s policies: what the plan expander puts
// between two readings at different targets — the RELOCATE_LAMP_AND_DETECTOR prompt, under
// reference.perDetectorPosition the reference block (mounting prompts, reference, and with
// dark.withEachReference the shutter prompt and dark) — and the reading, by the timing model for
// real devices (time scale 1). Measured by expanding a two-target plan; the same for every pose.
PoseCost FixedPoseCost(const v1::Plan& plan, const plan::RigDescription& rig);

}  // namespace brdf::adaptive
