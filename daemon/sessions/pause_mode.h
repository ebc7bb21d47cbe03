// How an operator's pause takes effect: the engine carries it out (SessionManager::Pause), the API
// reads it from PauseSessionRequest.mode (wire/enums.h) and hands it to the rig (api/rig_port.h).
#pragma once

namespace brdf::daemon {

enum class PauseMode {
  kDeferred,   // finish the step in progress, then pause (the session is pausing until then)
  kImmediate,  // cancel the step in progress now; resume redoes it
};

}  // namespace brdf::daemon
