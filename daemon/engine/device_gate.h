// DeviceGate: who may use an instrument right now — many sharers (stage moves and reads) or one
// owner (a meter exchange, a connection attempt) — with waits bounded by a deadline. It meets
// the standard Lockable / SharedLockable requirements (std::lock_guard, std::unique_lock,
// std::shared_lock work with it). Built on a mutex and a condition variable rather than
// std::shared_timed_mutex, whose timed waits ThreadSanitizer cannot follow.
#pragma once

#include <chrono>
#include <condition_variable>
#include <mutex>

namespace brdf::daemon {

class DeviceGate {
 public:
  void lock() {
    std::unique_lock l(mu_);
    cv_.wait(l, [this] { return Free(); });
    owned_ = true;
  }
  bool try_lock() {
    std::lock_guard l(mu_);
    if (!Free()) return false;
    owned_ = true;
    return true;
  }
  template <typename Rep, typename Period>
  bool try_lock_for(std::chrono::duration<Rep, Period> d) {
    std::unique_lock l(mu_);
    if (!cv_.wait_for(l, d, [this] { return Free(); })) return false;
    owned_ = true;
    return true;
  }
  void unlock() {
    {
      std::lock_guard l(mu_);
      owned_ = false;
    }
    cv_.notify_all();
  }

  void lock_shared() {
    std::unique_lock l(mu_);
    cv_.wait(l, [this] { return !owned_; });
    ++sharers_;
  }
  bool try_lock_shared() {
    std::lock_guard l(mu_);
    if (owned_) return false;
    ++sharers_;
    return true;
  }
  template <typename Rep, typename Period>
  bool try_lock_shared_for(std::chrono::duration<Rep, Period> d) {
    std::unique_lock l(mu_);
    if (!cv_.wait_for(l, d, [this] { return !owned_; })) return false;
    ++sharers_;
    return true;
  }
  void unlock_shared() {
    {
      std::lock_guard l(mu_);
      --sharers_;
    }
    cv_.notify_all();
  }

 private:
  bool Free() const { return !owned_ && sharers_ == 0; }

  std::mutex mu_;
  std::condition_variable cv_;
  bool owned_ = false;
  int sharers_ = 0;
};

}  // namespace brdf::daemon
