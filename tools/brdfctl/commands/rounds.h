// `brdfctl rounds <id>`: an adaptive session's rounds (ListAdaptiveRounds) against its plan's
// target and budgets (GetSession): a table of the rounds, the uncertainty left as bars, the last
// round's poses and cost (output/rounds_text.h) and, once it stopped, why. With --json: the
// ListAdaptiveRoundsResponse as one JSON line.
#pragma once

#include "tools/brdfctl/command.h"

namespace brdf::ctl {

void RegisterRoundsCommand(CommandRegistry& registry);

}  // namespace brdf::ctl
