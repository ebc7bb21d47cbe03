#include "daemon/rpc/work_permits.h"

#include <algorithm>
#include <chrono>

namespace brdf::daemon {
namespace {

// How often a waiting stream looks whether its call was cancelled.
constexpr std::chrono::milliseconds kCancelLook{500};

}  // namespace

WorkPermits::WorkPermits(int permits) : permits_(std::max(1, permits)) {}

int WorkPermits::HeldLocked(const std::string& token) const {
  const auto it = held_.find(token);
  return it == held_.end() ? 0 : it->second;
}

void WorkPermits::GrantLocked() {
  while (working_ < permits_ && !waiting_.empty()) {
    auto chosen = waiting_.begin();
    int fewest = HeldLocked((*chosen)->token);
    for (auto it = std::next(chosen); it != waiting_.end() && fewest > 0; ++it) {
      const int held = HeldLocked((*it)->token);
      if (held < fewest) {
        fewest = held;
        chosen = it;
      }
    }
    Waiter* waiter = *chosen;
    waiting_.erase(chosen);
    ++working_;
    ++held_[waiter->token];
    waiter->granted = true;
    waiter->granted_cv.NotifyOne();
  }
}

bool WorkPermits::Acquire(const std::string& token, const std::function<bool()>& cancelled) {
  MutexLock lock(mu_);
  Waiter me(token);
  waiting_.push_back(&me);
  GrantLocked();
  while (!me.granted) {
    if (cancelled()) {
      waiting_.remove(&me);
      return false;
    }
    me.granted_cv.WaitFor(mu_, kCancelLook);
  }
  return true;
}

void WorkPermits::Release(const std::string& token) {
  MutexLock lock(mu_);
  --working_;
  if (--held_[token] <= 0) held_.erase(token);
  GrantLocked();
}

int WorkPermits::working() const {
  MutexLock lock(mu_);
  return working_;
}

int WorkPermits::waiting() const {
  MutexLock lock(mu_);
  return static_cast<int>(waiting_.size());
}

}  // namespace brdf::daemon
