// The Control service's unary calls as subcommands: plans (validate, submit), the operator's verbs
// (start, pause, resume, abort, answer), and the read-only views (get, list, rig). Each prints the
// reply readably, or as one JSON object with --json, and returns an exit status (exit_codes.h).
#pragma once

#include <string>
#include <vector>

#include "tools/brdfctl/command.h"
#include "tools/brdfctl/command_context.h"

namespace brdf::ctl {

// ValidatePlan on a plan file: the summary when valid (exit 0); otherwise every problem with its
// JSON field path (exit 2). A file that does not parse is reported locally (exit 2).
// `time_scale`: the estimate for a rig that runs that many times faster (brdf-sim --time-scale).
int RunValidate(CommandContext& ctx, const std::string& plan_path, double time_scale = 1.0);

// SubmitPlan (start_now with --start). `quiet`: print only the new session's id.
int RunSubmit(CommandContext& ctx, const std::string& plan_path, bool start_now, bool quiet);

int RunStart(CommandContext& ctx, const std::string& session_id);
int RunPause(CommandContext& ctx, const std::string& session_id, bool immediate);
int RunResume(CommandContext& ctx, const std::string& session_id);
int RunAbort(CommandContext& ctx, const std::string& session_id, const std::string& reason);
int RunAnswer(CommandContext& ctx, const std::string& session_id, int step_index,
              const std::string& note);
int RunGet(CommandContext& ctx, const std::string& session_id);
// ListSessionEvents: the session's history of states, oldest first; one line per event,
// "<local time>  <state>  <reason>" (--json: one object per line).
int RunEvents(CommandContext& ctx, const std::string& session_id);

// ListSessions, every page (newest first), only `states` when given ("running", "paused", …);
// at most `limit` sessions (0: all).
// ListSessions' catalogue filters (empty: none), as brdfd and brdf-archive apply them.
struct ListFilters {
  std::string rig;
  std::string sample;  // the sample's id, or its name ignoring case
  std::string material;
  std::string tag;
};
int RunList(CommandContext& ctx, const std::vector<std::string>& states, unsigned limit,
            const ListFilters& filters = {});

// GetRigStatus: devices, axes, live pose, meter serial, the session holding the rig.
int RunRig(CommandContext& ctx);

// The subcommands, with their flags (command.h): validate and submit; start, pause, resume, abort
// and answer; get, events, list and rig.
void RegisterPlanCommands(CommandRegistry& registry);
void RegisterOperatorCommands(CommandRegistry& registry);
void RegisterViewCommands(CommandRegistry& registry);

}  // namespace brdf::ctl
