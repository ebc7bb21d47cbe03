// The seed design of an adaptive plan: the readings taken before any choice, so that the first
// round has something to judge. A retro-reflection scan at δ = 0 (lamp and detector together,
// θi = θo across the region: where retro-reflective coatings have their peak and where a
// warped parameterisation such as Dupuy & Jakob's starts), then at every detector position δ
// (and every dial position γ) a coarse space-filling set of holder poses — or at every n-th δ only
// (seed.deltaEvery), a cheaper seed: each δ left out spares a relocation and its reference.
//
// The space-filling set is deterministic: the Halton sequence in bases 2 and 3 maps to holder
// normals spread evenly over the upper hemisphere (sin α and β uniform, α ≥ 0 as geometry.md's
// rig reaches every isotropic point that way); each is kept when the pose is within the rig's
// travel and both directions lie in the plan's region, until the set is full or 512 draws per
// wanted pose have been tried. Angles are rounded to 0.01°. Pure.
#pragma once

#include <vector>

#include "core/adaptive/adaptive_spec.h"
#include "core/plan/rig_description.h"
#include "core/pose.h"

namespace brdf::adaptive {

// The seed poses of one (γ, δ): the detector and dial set once, then holder moves.
struct SeedGroup {
  double gamma_deg = 0;
  double delta_deg = 0;
  int retro_poses = 0;      // of `poses`, the retro-reflection scan's (δ = 0, first γ only)
  int wanted = 0;           // space-filling poses asked for
  std::vector<Pose> poses;  // model angles, in measurement order
};

// The groups in measurement order: γ outermost on a manual dial (each γ a prompt), δ outermost
// on a motorized γ axis; δ ascending; within a group α in 10° bands, β serpentine. A group that
// found fewer space-filling poses than wanted says so (wanted > poses.size() − retro_poses); one
// with none is kept (empty) so that validation can name its δ.
std::vector<SeedGroup> MakeSeedDesign(const AdaptiveSpec& spec, const plan::RigDescription& rig);

// All the groups' poses, in order.
std::vector<Pose> SeedPoses(const std::vector<SeedGroup>& groups);

// True when the pose (model angles) is within every travel limit of the rig (α, β, δ, and γ on a
// motorized axis, through the rig's convention) and both its directions lie in `region`.
bool Reachable(const Pose& model, const Region& region, const plan::RigDescription& rig);

// Orders poses of one (γ, δ) for short holder moves: α in 10° bands, β ascending in even bands
// and descending in odd ones (ties: α ascending). Deterministic.
void OrderForTravel(std::vector<Pose>& poses);

// The radical inverse of `index` in `base` (the Halton sequence's coordinate), in [0, 1).
double RadicalInverse(unsigned index, unsigned base);

}  // namespace brdf::adaptive
