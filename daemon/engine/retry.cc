#include "daemon/engine/retry.h"

#include <algorithm>
#include <chrono>

#include "daemon/wire/values.h"

namespace brdf::daemon {

bool Retryable(const Status& status) {
  switch (status.code()) {
    case StatusCode::kTimeout:
    case StatusCode::kDeviceError:
    case StatusCode::kProtocolError:
    case StatusCode::kDisconnected:
    case StatusCode::kFailedPrecondition:
      return true;
    default:
      return false;
  }
}

v1::Fault FaultFor(int step_index, const Status& status, std::uint32_t attempt, bool will_retry,
                   int last_quality_code, const std::string& reason) {
  v1::Fault fault;
  fault.set_step_index(step_index);
  fault.set_code(StatusCodeName(status.code()));
  fault.set_reason(reason.empty() ? status.message() : reason);
  fault.set_device_code(status.device_code());
  fault.set_attempt(attempt);
  fault.set_will_retry(will_retry);
  fault.set_last_quality_code(last_quality_code);
  *fault.mutable_time() = NowTimestamp();
  return fault;
}

Status RunWithRetry(const plan::RetrySettings& retry, std::uint32_t first_attempt,
                    const Clock& clock, const CancelToken& cancel,
                    const std::function<Status(std::uint32_t attempt)>& attempt_fn,
                    const AttemptFailed& failed) {
  const std::uint32_t max_attempts = std::max<std::uint32_t>(1, retry.max_attempts);
  Status last = Internal("no attempt was made");
  for (std::uint32_t attempt = first_attempt; attempt <= max_attempts; ++attempt) {
    if (attempt > 1) {
      const auto wait = std::chrono::milliseconds(plan::BackoffBeforeAttemptMs(retry, attempt));
      if (wait.count() > 0 && !clock.SleepFor(wait, &cancel)) {
        return Cancelled("cancelled while waiting to retry (" + cancel.reason() + ")");
      }
    }
    if (cancel.cancelled()) return Cancelled(cancel.reason());
    Status st = attempt_fn(attempt);
    if (st.ok()) return st;
    if (cancel.cancelled() || st.code() == StatusCode::kCancelled) {
      return Cancelled(st.message());
    }
    const bool will_retry = Retryable(st) && attempt < max_attempts;
    failed(st, attempt, max_attempts, will_retry);
    last = st;
    if (!will_retry) return st;
  }
  return last;
}

}  // namespace brdf::daemon
