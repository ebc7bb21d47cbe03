// Readable descriptions of sessions and of the things that happen to them (prompts, faults,
// plan summaries), shared by the control commands and `watch`.
#pragma once

#include <ostream>
#include <string>

#include "brdf/v1/brdf.pb.h"

namespace brdf::ctl {

// "45/120 steps, 30/90 sample readings (37%)".
std::string ProgressText(const v1::Progress& progress);

// One line: "3  running  45/120 steps …  demo (reduced grid)".
std::string SessionLine(const v1::Session& session);

// Several lines: state, progress, ETA, pending prompt (with the answer command), last fault,
// times, end reason, plan summary.
void PrintSessionDetail(std::ostream& out, const v1::Session& session);

// "prompt at step 7 (mount_white): <text>" and, on a second line, what the daemon assumes once
// answered.
void PrintPrompt(std::ostream& out, const v1::Prompt& prompt);

// "fault at step 12 (attempt 3): timeout: <reason> — will retry" (or "— session paused").
std::string FaultText(const v1::Fault& fault);

// "120 steps: 90 sample, 12 reference, 6 dark readings; 12 operator actions; about 5:00
// (at least 3:10)".
// The estimate is split in two: the rig's time (readings and moves; divided by `time_scale` for a
// simulated rig that runs that many times faster, e.g. brdf-sim --time-scale 8) and the operator's
// manual actions (about core/plan's operator_action_s each on a real rig; a script answering
// them on brdf-sim takes about none).
std::string PlanSummaryText(const v1::PlanSummary& summary, double time_scale = 1.0);

}  // namespace brdf::ctl
