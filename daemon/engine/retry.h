// The plan's retry policy applied to one step's device work, and the fault event a failed
// attempt publishes. Used by the executor's move and reading handlers (DESIGN.md, "Failures").
#pragma once

#include <cstdint>
#include <functional>
#include <string>

#include "brdf/v1/brdf.pb.h"
#include "core/call_context.h"
#include "core/clock.h"
#include "core/plan/plan_settings.h"
#include "core/status.h"

namespace brdf::daemon {

// Errors a later attempt may cure: the device was slow, busy, alarmed, disconnected or garbled
// (kTimeout, kDeviceError, kProtocolError, kDisconnected, kFailedPrecondition). Not: a pose
// beyond travel, a bad configuration, a bug.
bool Retryable(const Status& status);

// The fault event of `status` at step `step_index`: its code name, `reason` (the status's message
// when empty), device code, the attempt, whether another follows, the meter's last quality code,
// and the time now.
v1::Fault FaultFor(int step_index, const Status& status, std::uint32_t attempt, bool will_retry,
                   int last_quality_code, const std::string& reason = "");

// One failed attempt, as RunWithRetry reports it (before deciding whether to go on).
using AttemptFailed = std::function<void(const Status& status, std::uint32_t attempt,
                                         std::uint32_t max_attempts, bool will_retry)>;

// Runs `attempt` for attempts first_attempt … max(1, retry.max_attempts) until one succeeds.
// Before an attempt after the first it waits plan::BackoffBeforeAttemptMs on `clock`. A failed
// attempt is reported to `failed`; another follows only when the error is Retryable and attempts
// are left. Returns Ok, the last attempt's error, kCancelled when `cancel` fired (before an
// attempt, during the backoff or under an attempt, whose error then becomes kCancelled with its
// message; nothing is reported for it), or kInternal when first_attempt is past the last.
Status RunWithRetry(const plan::RetrySettings& retry, std::uint32_t first_attempt,
                    const Clock& clock, const CancelToken& cancel,
                    const std::function<Status(std::uint32_t attempt)>& attempt,
                    const AttemptFailed& failed);

}  // namespace brdf::daemon
