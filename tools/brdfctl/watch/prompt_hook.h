// `watch --on-prompt CMD`: before brdfctl confirms a prompt it runs CMD (with /bin/sh -c), so that
// a script can do the manual action first — on brdf-sim, mount the white standard the way an
// operator would (deploy/quickstart.sh runs `brdfctl sim-mount from-prompt`). CMD sees the prompt
// in its environment:
//   BRDF_SESSION_ID      the session
//   BRDF_PROMPT_STEP     the prompt's step index
//   BRDF_PROMPT_KIND     relocate_detector, mount_white, mount_sample, relocate_lamp_and_detector,
//                        close_shutter or set_gamma_dial
//   BRDF_PROMPT_TEXT     the instruction shown to the operator
//   BRDF_PROMPT_ALPHA, _BETA, _GAMMA, _DELTA   the pose the rig will be in, degrees
//   BRDF_PROMPT_THETA_I, _PHI_I, _THETA_O, _PHI_O   the sample-fixed method's lamp and detector
//                        directions to set up, degrees (only when the prompt has a target)
// CMD's standard output goes to brdfctl's standard error, so that --json output stays parsable.
// A CMD that fails (non-zero exit) leaves the prompt unanswered.
#pragma once

#include <string>
#include <utility>
#include <vector>

#include "brdf/v1/brdf.pb.h"
#include "core/status.h"

namespace brdf::ctl {

// The variables above, as name/value pairs.
std::vector<std::pair<std::string, std::string>> PromptEnvironment(const std::string& session_id,
                                                                   const v1::Prompt& prompt);

// Runs `command` and waits for it. OK when it exits 0; kFailedPrecondition naming the exit status
// (or the signal) otherwise; kIoError when it cannot be started.
Status RunPromptHook(const std::string& command, const std::string& session_id,
                     const v1::Prompt& prompt);

}  // namespace brdf::ctl
