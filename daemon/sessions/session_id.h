// What names a session and who acts on it, for every room above the store: the engine that runs
// sessions, the index that interpolates them, the API and brdf-archive that serve them. Kept
// apart from the engine so that those who only read sessions do not depend on it.
#pragma once

#include <cstdint>
#include <string>

#include "core/status.h"

namespace brdf::daemon {

// A session's id: the store's row id, positive, as SubmitPlan returned it.
using SessionId = std::int64_t;

// Who asks: the role of the caller's token ("operator", "analyst") and the token's name.
struct Actor {
  std::string role;
  std::string name;
};

// "17" → 17. kInvalidArgument naming `field` ("session_id") when the text is not a positive id;
// the message quotes at most a short printable prefix of `text`.
Result<SessionId> ParseSessionId(const std::string& text, const std::string& field = "session_id");

}  // namespace brdf::daemon
