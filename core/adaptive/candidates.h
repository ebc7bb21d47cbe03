// The poses a round chooses from: a lattice over the holder's angles at every (γ, δ) of the
// plan, α from 0° to 90° and β over (−180°, 180°] every kCandidateStepDeg, kept where the pose is
// within the rig's travel and both directions lie in the region (seed_design.h: Reachable).
// Deterministic, in (γ, δ, α, β) order. Pure.
#pragma once

#include <vector>

#include "core/adaptive/adaptive_spec.h"
#include "core/plan/rig_description.h"
#include "core/pose.h"

namespace brdf::adaptive {

std::vector<Pose> CandidatePoses(const AdaptiveSpec& spec, const plan::RigDescription& rig,
                                 double step_deg = kCandidateStepDeg);

}  // namespace brdf::adaptive
