// An adaptive session's rounds as text (docs/adaptive.md, "Every choice explained"), for `watch`
// and `rounds`: the uncertainty left round by round against the plan's target, what was spent
// against its budgets, and what the next round measures. Every line fits 80 columns.
#pragma once

#include <ostream>
#include <string>
#include <vector>

#include "brdf/v1/brdf.pb.h"
#include "brdf/v1/plan.pb.h"

namespace brdf::ctl {

// "target U (k = 2) ≤ 0.05; budget 464 readings, 38:00 rig time, 60 prompts" (the limits set).
std::string AdaptiveGoalText(const v1::Adaptive& adaptive);

// `text` broken at spaces into lines of at most 80 columns, the later ones indented by two
// (a word longer than a line is cut, ending in "…").
std::vector<std::string> WrapText(const std::string& text);

// The target's level (expanded uncertainty or expected error); 0 when neither is set.
double TargetLevel(const v1::Adaptive& adaptive);

// "δ 45° → 56.25° → 78.75°": the round's detector positions in measurement order, each once
// per visit (a relocation between two).
std::string DeltaPathText(const v1::AdaptiveRound& round);

// "3 round(s) so far; uncertainty left 0.739 → 0.461 → 0.277" (the earliest values left out,
// "… →", where all would pass 80 columns).
std::string RoundsSoFarText(const std::vector<v1::AdaptiveRound>& rounds);

// A stored round as lines of at most 80 columns (`adaptive`: the session's plan, for its target
// and budgets; a limit not set is left out):
//   round 2 (from 200 of 464 readings): uncertainty left 0.461, target 0.05
//     spent 17:14 of 38:00 rig time, 31 of 60 prompts; predicted gain 0.104
//     next: 24 poses, steps 475–527, +4:02 rig time, +2 prompts
//     δ 45° → 56.25° → 78.75°
//     first poses: α 10° β −35° γ 0° δ 45°; α 15° β −30° γ 0° δ 45°
// In the sample-fixed form (adaptive.sample_fixed set) the last two lines are one, the directions
// where the operator will place lamp and detector:
//     first directions: θi 50° θo 5° φ 130°; θi 50° θo 5° φ 100°; …
// and `rounds`' table gives each round's θi range instead of its δ range.
std::vector<std::string> AdaptiveRoundLines(const v1::AdaptiveRound& round,
                                            const v1::Adaptive& adaptive);

// The stop, two lines (three where the spend passes 80 columns):
//   adaptive stop: reading budget spent; uncertainty left 0.0412 (target 0.05)
//     after 3 round(s): 212 of 464 readings, 31:30 of 38:00 rig time,
//     40 of 60 prompts
std::vector<std::string> AdaptiveStopLines(const v1::AdaptiveStop& stop,
                                           const v1::Adaptive& adaptive);

// `brdfctl rounds`: the goal, a table of the rounds (readings chosen from, uncertainty left,
// predicted gain, rig time and prompts spent before each, poses, δ), the uncertainty left as bars
// against the target, and the last round's lines (what the rig measures, or measured, last).
void PrintRoundsTable(std::ostream& out, const std::vector<v1::AdaptiveRound>& rounds,
                      const v1::Adaptive& adaptive);

}  // namespace brdf::ctl
