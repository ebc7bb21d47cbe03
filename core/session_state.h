// The session state machine, as data. Every session is in exactly one state; operators' verbs and
// the executor's events move it along the table below, and anything not in the table is refused
// with FailedPrecondition naming the state and the verb. The executor owns the side effects
// (cancelling a measurement, waiting for the rig); this file only says what may follow what.
//
// clang-format off
//   state \ event     start  pause_def pause_imm resume  abort   answer  prompt  step_done fault  finish    error
//   queued            run*   -         -         -       aborted -       -       -         -      -         failed
//   running           -      pausing   paused    -       aborted -       await   running   paused completed failed
//   pausing           -      pausing   paused    running aborted -       paused  paused    paused completed failed
//   paused            -      paused    paused    run*    aborted -       -       -         paused -         failed
//   awaiting_operator -      paused    paused    -       aborted running -       -         paused -         failed
//   completed, aborted, failed: terminal; every event is refused.
// clang-format on
//   run* = running when the rig is free, else queued (one session runs on the rig at a time).
//   Pause while pausing or paused is idempotent; pause immediate while pausing upgrades it.
#pragma once

#include <string>

#include "core/status.h"

namespace brdf {

enum class SessionState {
  kQueued,
  kRunning,
  kPausing,
  kPaused,
  kAwaitingOperator,
  kCompleted,
  kAborted,
  kFailed,
};

enum class SessionEvent {
  kStart,           // operator: start (or the queue hands the rig to this session)
  kPauseDeferred,   // operator: pause after the current step
  kPauseImmediate,  // operator: cancel the in-flight step now; resume redoes it
  kResume,          // operator: go on (after a pause or a fault)
  kAbort,           // operator: stop for good, keeping the data
  kAnswer,          // operator: the prompted manual action is done
  kPrompt,          // executor: reached a step that needs the operator
  kStepDone,        // executor: a step finished (and was committed)
  kFault,           // executor: a device fault survived the retry policy
  kFinish,          // executor: the last step finished
  kError,           // executor: an internal error that makes going on unsafe
};

const char* SessionStateName(SessionState s);  // "queued", "running", ..., "awaiting_operator"
Result<SessionState> ParseSessionState(const std::string& name);
const char* SessionEventName(SessionEvent e);  // "start", "pause_deferred", ...
// The event as the operator says it, for messages: "pause", "pause (immediately)", "resume",
// "answer a prompt of" (read as "cannot <verb> a session that is paused").
const char* SessionEventVerb(SessionEvent e);

bool IsTerminal(SessionState s);

// The next state, or FailedPrecondition ("cannot resume a session that is running").
// `rig_free` matters only for start and resume: when another session holds the rig, they queue.
Result<SessionState> NextState(SessionState from, SessionEvent event, bool rig_free = true);

}  // namespace brdf
