// One round of an adaptive session: which poses to measure next. Greedy: from the candidate
// poses, repeatedly take the one with the largest predicted gain per second — the fall of the
// integrated, cosine-weighted uncertainty (uncertainty_model.h) over what the reading costs from
// where the rig then is (round_cost.h: move, reading, and a δ change costed as its prompt and
// reference block) — and count it as measured (UncertaintyMap::Assume) before the next pick;
// stop at the round's size, when nothing affordable gains anything, or at the budget. The
// candidates are the caller's plus finer ones near the readings and near the coarse candidates
// that gain most (refine_candidates.h), so that a narrow peak between lattice poses can still be
// reached. Then the batch is grouped by detector position (the rig's present δ first, then in
// order of first pick), each group ordered for short moves, so the operator relocates the
// detector once per δ per round; the batch is costed again in that order and cut from the end to
// fit the budget.
//
// Because of the grouping, a δ change is paid once per round: a pick at a detector position the
// round has reached already is charged its move and reading alone. And a round relocates the
// operator's detector (a δ or dial change that is a prompt) at most `max_relocations` times, so
// that each relocation, and what the policies put after it, is amortised over the picks it
// opens instead of being paid again a few picks later (docs/adaptive.md, "Fewer relocations").
//
// Deterministic: the same readings, candidates (in any order), rig position, spend and budget
// give the same poses in the same order; equal scores go to the smaller (δ, γ, α, β).
#pragma once

#include <span>
#include <vector>

#include "core/adaptive/adaptive_spec.h"
#include "core/adaptive/refine_candidates.h"
#include "core/adaptive/round_cost.h"
#include "core/adaptive/uncertainty_model.h"
#include "core/pose.h"

namespace brdf::adaptive {

// What a session has used so far (the seed design's included).
struct Spend {
  int readings = 0;
  double seconds = 0;
  int prompts = 0;
};

// The first limit of `budget` (readings, rig time, prompts) that `spent` plus `more` would pass
// (1e-9 s of slack), or kContinue when it stays within every one.
StopReason LimitPassed(const Budget& budget, const Spend& spent, const PoseCost& more,
                       int readings);
// True when `spent` plus `more` stays within every limit of `budget`.
bool WithinBudget(const Budget& budget, const Spend& spent, const PoseCost& more, int readings);

struct ChosenPose {
  Pose pose;                  // model angles
  double predicted_gain = 0;  // when it was picked, with the earlier picks assumed
};

struct Round {
  std::vector<ChosenPose> poses;  // in measurement order
  double predicted_gain = 0;      // sum of the picks' gains
  PoseCost cost;                  // of the poses in measurement order, from the rig's pose
  // The first budget limit that left out a pose predicted to gain (kContinue: none did). For an
  // empty round this says why it is empty: the budget, not the uncertainty (stop_rule.h).
  StopReason limited_by = StopReason::kContinue;
};

struct RoundInput {
  std::span<const ReadingSoFar> readings;  // every sample reading so far
  std::span<const Pose> candidates;        // model angles (candidates.h)
  Pose rig_at;                             // where the rig is (model angles): the last reading
  Spend spent;
  Budget budget;
  // Poses the rig could not read (an adaptive session's skipped steps, model angles): never
  // chosen, as if measured, though no reading informs the map there.
  std::span<const Pose> unreadable = {};
};

// A round relocates the operator's detector at most once (see RoundOptions::max_relocations).
inline constexpr int kDefaultMaxRelocations = 1;

struct RoundOptions {
  int max_readings = kDefaultRoundReadings;
  // false, for comparison only: δ changes are not charged when picking and the batch is measured
  // in pick order (it is still costed, prompts included, for the budget).
  bool group_by_delta = true;
  // The finer candidates added to the caller's (refine_candidates.h); levels 0: none.
  RefineOptions refine = {};
  // Detector positions (δ, γ) a round may move to that cost the operator a relocation (a prompt:
  // a manual detector or dial), beyond the rig's present one; -1: any number. Grouped rounds
  // only; not in the sample-fixed form (there every pose is a prompt).
  int max_relocations = kDefaultMaxRelocations;
};

// The next round; empty when nothing affordable is predicted to gain anything (the caller
// stops: stop_rule.h). A candidate equal to a reading's pose, to an unreadable pose or to an
// earlier pick is skipped; a pick may be a finer candidate, not one of input.candidates.
Round ChooseRound(const RoundInput& input, const UncertaintyModel& model, const RoundCost& cost,
                  const RoundOptions& options = {});
// The same from a map already built from input.readings (model.Map(input.readings)), for a
// caller that read its Remaining() first; the map takes the round's picks (Assume).
Round ChooseRound(const RoundInput& input, UncertaintyMap& map, const RoundCost& cost,
                  const RoundOptions& options = {});

}  // namespace brdf::adaptive
