// Readable descriptions of sessions and of the things that happen to them (prompts, faults,
// plan summaries), shared by the control commands and `watch`.
#pragma once

#include <ostream>
#include <string>

#include "brdf/v1/brdf.pb.h"

namespace brdf::ctl {

// "45/120 steps, 30/90 sample readings (37%)".
std::string ProgressText(const v1::Progress& progress);

// "380–780 nm every 1 nm (401 bands)".
std::string GridText(const v1::WavelengthGrid& grid);

// One line: "3  running  45/120 steps …  demo (reduced grid)  401 bands" (bands once it has a
// reading).
std::string SessionLine(const v1::Session& session);

// Several lines: state, progress, ETA, pending prompt (with the answer command), last fault,
// times, end reason, plan summary.
void PrintSessionDetail(std::ostream& out, const v1::Session& session);

// "prompt at step 7 (mount_white): <text>" and, on a second line, what the daemon assumes once
// answered.
void PrintPrompt(std::ostream& out, const v1::Prompt& prompt);

// "fault at step 12 (attempt 3): timeout: <reason> — will retry" (or "— session paused", or for
// an adaptive session's skipped pose, "step skipped: …", "— the session goes on").
std::string FaultText(const v1::Fault& fault);

// "120 steps: 90 sample, 12 reference, 6 dark readings; 12 operator actions; rig time about 5:00
// (at least 3:10); plus the operator's 12 prompts, not counted (about 30 s each by hand)".
// The estimate is split in two: the rig's time (readings, moves and the daemon's own waits, as
// the daemon estimated them; for a simulated rig running `time_scale` times faster when the
// summary was asked for at that scale, with `real_rig_s`, when > 0, the same plan's rig time on a
// real rig) and the operator's prompts, which the estimate cannot know (a person at the rig:
// about core/plan's operator_action_s each; a script answering them on brdf-sim: about none).
std::string PlanSummaryText(const v1::PlanSummary& summary, double time_scale = 1.0,
                            double real_rig_s = 0);

// The rig's part of a summary's estimate: estimated_duration_s without the operator's prompts.
double RigSeconds(const v1::PlanSummary& summary);

}  // namespace brdf::ctl
