#include "drivers/serial/context_wait.h"

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

}  // namespace brdf::drivers::serial
