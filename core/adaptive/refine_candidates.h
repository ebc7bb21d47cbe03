// Finer candidates where the gains are. The plan's candidate lattice (candidates.h, every 5°)
// cannot put a reading nearer than its spacing to a feature such as a narrow specular lobe; once
// the lattice's poses beside it are measured, no candidate is left there and the uncertainty
// stops falling. A lattice every 2.5° everywhere would lower that floor but costs four times the
// round. So a round refines locally, level by level: at level k the poses step / 2^k away in α
// and β (the 8 neighbours, at the same γ and δ) from each anchor — every reading so far and the
// best of the level before (the coarse candidates at level 1) — are scored by the map's
// predicted gain, and the `keep` best that gain anything become candidates too. A finer pose so
// goes only near where a reading was taken or where a coarser candidate gains most.
//
// Deterministic: the same readings, candidates (in any order) and map give the same poses, in
// (δ, γ, α, β) order; angles are rounded to 0.01°; a pose equal to a reading's or a candidate's
// is left out, as is one the rig cannot take (RoundCost::CanReach). None for a sample-fixed plan
// (RoundCost::sample_fixed): the operator sets its poses by hand in whole degrees, so every
// caller of ChooseRound gets only the plan's candidates there. Pure.
#pragma once

#include <span>
#include <vector>

#include "core/adaptive/adaptive_spec.h"
#include "core/adaptive/round_cost.h"
#include "core/adaptive/uncertainty_model.h"
#include "core/pose.h"

namespace brdf::adaptive {

struct RefineOptions {
  double step_deg = kCandidateStepDeg;  // the coarse candidates' spacing
  int levels = 2;                       // 2: poses at step/2 and step/4
  int keep = 96;                        // poses kept per level, the best by predicted gain
};

// The finer candidates (not including `candidates` themselves), in (δ, γ, α, β) order.
std::vector<Pose> RefinedCandidates(std::span<const ReadingSoFar> readings,
                                    std::span<const Pose> candidates, const UncertaintyMap& map,
                                    const RoundCost& cost, const RefineOptions& options = {});

}  // namespace brdf::adaptive
