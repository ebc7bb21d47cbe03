// When an adaptive session stops: at the target, or when a budget is spent, checked before each
// round; a round that finds nothing affordable worth measuring (ChooseRound's empty round) also
// ends it. The first reason that holds is the one given, in the order of the enum.
#pragma once

#include "core/adaptive/adaptive_spec.h"
#include "core/adaptive/round_chooser.h"

namespace brdf::adaptive {

// "target reached", "reading budget spent", …; "continue".
const char* StopReasonText(StopReason reason);

// Before a round: `remaining` is UncertaintyMap::Remaining() for the readings so far.
StopReason ShouldStop(double remaining, const Target& target, const Budget& budget,
                      const Spend& spent);

// After choosing: kContinue for a round with poses. For an empty round, the budget that left out
// a pose predicted to gain (Round::limited_by: one more reading would pass it, though it is not
// yet reached), else kNothingToGain.
StopReason AfterChoosing(const Round& round);

}  // namespace brdf::adaptive
