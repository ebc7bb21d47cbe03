// `brdfctl watch <id>`: follows a session (WatchSession) until it ends.
//   - On a terminal: a live progress line (watch/progress_line.h) — done/total, ETA, the pose
//     of the latest reading, its quality code — with state changes, prompts and faults printed
//     above it.
//   - Otherwise: one plain line per event. With --json: each SessionEvent as one JSON line.
// At an operator prompt it offers to confirm: "[y/N]" on a terminal (or with --ask), while it
// keeps showing what the session does; a question whose session leaves awaiting_operator (a pause,
// an abort, an answer from elsewhere) is withdrawn, unanswered, and --on-prompt is not run.
// --auto-confirm answers every prompt; without either it waits for someone to answer
// (`brdfctl answer`). Every state change is shown with its reason (pausing, paused and why,
// faults, resumed, queued behind another session).
// --on-prompt CMD runs before each confirmation (watch/prompt_hook.h).
// The ETA is the daemon's, rescaled to the pace the rig shows while watched
// (watch/eta_calibrator.h).
// Exit: 0 when the session completed, 4 when it ended aborted or failed (or paused, with
// --exit-on-pause), else exit_codes.h.
#pragma once

#include <string>

#include "tools/brdfctl/command.h"
#include "tools/brdfctl/command_context.h"

namespace brdf::ctl {

struct WatchOptions {
  std::string session_id;
  bool auto_confirm = false;   // answer every prompt without asking
  std::string on_prompt;       // shell command run before each confirmation; empty: none
  bool exit_on_pause = false;  // stop watching (exit 4) when the session pauses (e.g. a fault)
  bool progress_bar = false;   // redraw one progress line (stdout is a terminal, not --json)
  bool ask = false;            // ask y/N on standard input (stdin and stdout are terminals)
  int width = 80;              // terminal columns for the progress line
};

int RunWatch(CommandContext& ctx, const WatchOptions& options);

// `watch`, with its flags (command.h); on a terminal it draws the progress line and asks y/N.
void RegisterWatchCommand(CommandRegistry& registry);

}  // namespace brdf::ctl
