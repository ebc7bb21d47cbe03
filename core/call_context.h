// Deadlines and cancellation for every call that may block. A device call takes a CallContext;
// it returns kTimeout when the deadline passes and kCancelled when the token is cancelled, and
// never blocks past either.
#pragma once

#include <atomic>
#include <chrono>
#include <memory>
#include <string>

#include "core/clock.h"
#include "core/mutex.h"

namespace brdf {

// Shared flag that a controller sets (pause immediate, abort, shutdown) and workers poll or wait
// on. Cheap to copy: copies share state.
class CancelToken {
 public:
  CancelToken() : state_(std::make_shared<State>()) {}

  void Cancel(std::string reason = "cancelled");
  bool cancelled() const { return state_->cancelled.load(std::memory_order_acquire); }
  std::string reason() const;
  // Waits up to `d` for cancellation; true if cancelled.
  bool WaitFor(std::chrono::steady_clock::duration d) const;

 private:
  struct State {
    std::atomic<bool> cancelled{false};
    mutable Mutex mu;
    mutable CondVar cv;
    std::string reason GUARDED_BY(mu);
  };
  std::shared_ptr<State> state_;
};

class CallContext {
 public:
  using TimePoint = std::chrono::steady_clock::time_point;

  // A context that expires `timeout` from now on `clock`, optionally cancelled by `cancel`.
  static CallContext WithTimeout(std::chrono::steady_clock::duration timeout,
                                 CancelToken cancel = CancelToken(),
                                 const Clock& clock = Clock::Real());

  CallContext(TimePoint deadline, CancelToken cancel, const Clock& clock)
      : deadline_(deadline), cancel_(std::move(cancel)), clock_(&clock) {}

  TimePoint deadline() const { return deadline_; }
  const CancelToken& cancel() const { return cancel_; }
  const Clock& clock() const { return *clock_; }

  bool cancelled() const { return cancel_.cancelled(); }
  bool expired() const { return clock_->Now() >= deadline_; }
  std::chrono::steady_clock::duration remaining() const;

  // A child context with the earlier of this deadline and now + timeout; same cancel token.
  CallContext Narrow(std::chrono::steady_clock::duration timeout) const;

 private:
  TimePoint deadline_;
  CancelToken cancel_;
  const Clock* clock_;
};

}  // namespace brdf
