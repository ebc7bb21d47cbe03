#include "core/call_context.h"

#include <algorithm>
#include <thread>

namespace brdf {

namespace {
class RealClock final : public Clock {
 public:
  TimePoint Now() const override { return std::chrono::steady_clock::now(); }
  bool SleepFor(Duration d, const CancelToken* cancel) const override {
    if (cancel == nullptr) {
      std::this_thread::sleep_for(d);
      return true;
    }
    return !cancel->WaitFor(d);
  }
};
}  // namespace

const Clock& Clock::Real() {
  static const RealClock clock;
  return clock;
}

void CancelToken::Cancel(std::string reason) {
  {
    MutexLock lock(state_->mu);
    if (state_->cancelled.load()) return;
    state_->reason = std::move(reason);
    state_->cancelled.store(true, std::memory_order_release);
  }
  state_->cv.NotifyAll();
}

std::string CancelToken::reason() const {
  MutexLock lock(state_->mu);
  return state_->reason;
}

bool CancelToken::WaitFor(std::chrono::steady_clock::duration d) const {
  MutexLock lock(state_->mu);
  return state_->cv.WaitFor(state_->mu, d, [&] { return state_->cancelled.load(); });
}

CallContext CallContext::WithTimeout(std::chrono::steady_clock::duration timeout,
                                     CancelToken cancel, const Clock& clock) {
  return CallContext(clock.Now() + timeout, std::move(cancel), clock);
}

std::chrono::steady_clock::duration CallContext::remaining() const {
  return std::max(std::chrono::steady_clock::duration::zero(), deadline_ - clock_->Now());
}

CallContext CallContext::Narrow(std::chrono::steady_clock::duration timeout) const {
  return CallContext(std::min(deadline_, clock_->Now() + timeout), cancel_, *clock_);
}

}  // namespace brdf
