#include "drivers/serial/context_wait.h"

#include <algorithm>
#include <string>

namespace brdf::drivers::serial {

Status WaitChecked(std::chrono::steady_clock::duration d, const CallContext& ctx,
                   std::string_view what) {
  const Clock& clock = ctx.clock();
  const auto end = clock.Now() + d;
  if (end > ctx.deadline()) {
    return Timeout("deadline too close for " + std::string(what) + ": give the call more time");
  }
  while (true) {
    if (ctx.cancelled()) {
      return Cancelled(std::string(what) + " cancelled (" + ctx.cancel().reason() + ")");
    }
    const auto now = clock.Now();
    if (now >= end) return Status::Ok();
    clock.SleepFor(end - now, &ctx.cancel());
  }
}

std::optional<std::chrono::steady_clock::time_point> LateReplyDeadline(
    std::chrono::steady_clock::time_point sent_at, std::chrono::steady_clock::duration timeout,
    std::chrono::steady_clock::time_point now, bool timed_out,
    std::chrono::steady_clock::duration timed_out_cap) {
  auto until = sent_at + timeout;
  if (timed_out) until = std::max(until, now + std::min(timeout, timed_out_cap));
  if (until <= now) return std::nullopt;
  return until;
}

}  // namespace brdf::drivers::serial
