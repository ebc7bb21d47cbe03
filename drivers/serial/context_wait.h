// Sleeping inside a device call without ever outliving its CallContext: the wait ends at once on
// cancellation and is refused when the deadline would pass first.
#pragma once

#include <chrono>
#include <string_view>

#include "core/call_context.h"
#include "core/status.h"

namespace brdf::drivers::serial {

// Sleeps `d` on the context's clock. kCancelled when cancelled meanwhile; kTimeout (without
// sleeping) when the deadline comes before `d` is over. `what` names the wait in messages
// ("waiting for the meter to wake").
Status WaitChecked(std::chrono::steady_clock::duration d, const CallContext& ctx,
                   std::string_view what);

}  // namespace brdf::drivers::serial
