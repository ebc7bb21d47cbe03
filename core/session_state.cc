#include "core/session_state.h"

namespace brdf {

const char* SessionStateName(SessionState s) {
  switch (s) {
    case SessionState::kQueued:
      return "queued";
    case SessionState::kRunning:
      return "running";
    case SessionState::kPausing:
      return "pausing";
    case SessionState::kPaused:
      return "paused";
    case SessionState::kAwaitingOperator:
      return "awaiting_operator";
    case SessionState::kCompleted:
      return "completed";
    case SessionState::kAborted:
      return "aborted";
    case SessionState::kFailed:
      return "failed";
  }
  return "unknown";
}

Result<SessionState> ParseSessionState(const std::string& name) {
  for (SessionState s : {SessionState::kQueued, SessionState::kRunning, SessionState::kPausing,
                         SessionState::kPaused, SessionState::kAwaitingOperator,
                         SessionState::kCompleted, SessionState::kAborted, SessionState::kFailed}) {
    if (name == SessionStateName(s)) return s;
  }
  return InvalidArgument("unknown session state '" + name + "'");
}

const char* SessionEventVerb(SessionEvent e) {
  switch (e) {
    case SessionEvent::kStart:
      return "start";
    case SessionEvent::kPauseDeferred:
      return "pause";
    case SessionEvent::kPauseImmediate:
      return "pause (immediately)";
    case SessionEvent::kResume:
      return "resume";
    case SessionEvent::kAbort:
      return "abort";
    case SessionEvent::kAnswer:
      return "answer a prompt of";
    case SessionEvent::kPrompt:
      return "prompt the operator in";
    case SessionEvent::kStepDone:
      return "complete a step of";
    case SessionEvent::kFault:
      return "record a fault in";
    case SessionEvent::kFinish:
      return "finish";
    case SessionEvent::kError:
      return "fail";
  }
  return "change";
}

const char* SessionEventName(SessionEvent e) {
  switch (e) {
    case SessionEvent::kStart:
      return "start";
    case SessionEvent::kPauseDeferred:
      return "pause_deferred";
    case SessionEvent::kPauseImmediate:
      return "pause_immediate";
    case SessionEvent::kResume:
      return "resume";
    case SessionEvent::kAbort:
      return "abort";
    case SessionEvent::kAnswer:
      return "answer";
    case SessionEvent::kPrompt:
      return "prompt";
    case SessionEvent::kStepDone:
      return "step_done";
    case SessionEvent::kFault:
      return "fault";
    case SessionEvent::kFinish:
      return "finish";
    case SessionEvent::kError:
      return "error";
  }
  return "unknown";
}

bool IsTerminal(SessionState s) {
  return s == SessionState::kCompleted || s == SessionState::kAborted || s == SessionState::kFailed;
}

Result<SessionState> NextState(SessionState from, SessionEvent event, bool rig_free) {
  using S = SessionState;
  using E = SessionEvent;
  const S run_or_queue = rig_free ? S::kRunning : S::kQueued;
  if (!IsTerminal(from)) {
    if (event == E::kAbort) return S::kAborted;
    if (event == E::kError) return S::kFailed;
  }
  switch (from) {
    case S::kQueued:
      if (event == E::kStart) return run_or_queue;
      break;
    case S::kRunning:
      switch (event) {
        case E::kPauseDeferred:
          return S::kPausing;
        case E::kPauseImmediate:
          return S::kPaused;
        case E::kPrompt:
          return S::kAwaitingOperator;
        case E::kStepDone:
          return S::kRunning;
        case E::kFault:
          return S::kPaused;
        case E::kFinish:
          return S::kCompleted;
        default:
          break;
      }
      break;
    case S::kPausing:
      switch (event) {
        case E::kPauseDeferred:
          return S::kPausing;
        case E::kPauseImmediate:
        case E::kPrompt:  // the pause takes effect before the operator is asked
        case E::kStepDone:
        case E::kFault:
          return S::kPaused;
        case E::kResume:
          return S::kRunning;  // the pause had not taken effect yet
        case E::kFinish:
          return S::kCompleted;
        default:
          break;
      }
      break;
    case S::kPaused:
      switch (event) {
        case E::kPauseDeferred:
        case E::kPauseImmediate:
        case E::kFault:
          return S::kPaused;
        case E::kResume:
          return run_or_queue;
        default:
          break;
      }
      break;
    case S::kAwaitingOperator:
      switch (event) {
        case E::kAnswer:
          return S::kRunning;
        case E::kPauseDeferred:
        case E::kPauseImmediate:
        case E::kFault:
          return S::kPaused;
        default:
          break;
      }
      break;
    case S::kCompleted:
    case S::kAborted:
    case S::kFailed:
      break;
  }
  return FailedPrecondition(std::string("cannot ") + SessionEventVerb(event) +
                            " a session that is " + SessionStateName(from));
}

}  // namespace brdf
