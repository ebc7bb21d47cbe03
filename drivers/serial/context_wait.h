// Sleeping inside a device call without ever outliving its CallContext: the wait ends at once on
// cancellation and is refused when the deadline would pass first.
#pragma once

#include <chrono>
#include <optional>
#include <string_view>

#include "core/call_context.h"
#include "core/status.h"

namespace brdf::drivers::serial {

// Sleeps `d` on the context's clock. kCancelled when cancelled meanwhile; kTimeout (without
// sleeping) when the deadline comes before `d` is over. `what` names the wait in messages
// ("waiting for the meter to wake").
Status WaitChecked(std::chrono::steady_clock::duration d, const CallContext& ctx,
                   std::string_view what);

// Until when the command after one left unanswered first waits for that reply, to discard it:
// a reply read after the next command went out would be taken for its answer, and every later
// reply would be one behind. A command cancelled early may be answered until sent_at + timeout;
// one that timed out is already late, so the wait is one more timeout from `now`, capped at
// `timed_out_cap` (a meter slow once answers soon after; a silent one costs at most the cap per
// retry). nullopt: nothing to wait for.
std::optional<std::chrono::steady_clock::time_point> LateReplyDeadline(
    std::chrono::steady_clock::time_point sent_at, std::chrono::steady_clock::duration timeout,
    std::chrono::steady_clock::time_point now, bool timed_out,
    std::chrono::steady_clock::duration timed_out_cap = std::chrono::seconds(1));

}  // namespace brdf::drivers::serial
