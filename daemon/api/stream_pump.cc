#include "daemon/api/stream_pump.h"

#include <algorithm>
#include <utility>

#include "daemon/rpc/thread_priority.h"

namespace brdf::daemon {

StreamPump::StreamPump(int threads) {
  for (int i = 0; i < std::max(threads, 1); ++i) {
    threads_.emplace_back([this] {
      NameThisThread("stream-pump");
      (void)SetThisThreadNice(kStreamNice);
      Run();
    });
  }
}

StreamPump::~StreamPump() {
  Stop();
}

void StreamPump::Post(Task task) {
  {
    MutexLock lock(mu_);
    if (stop_) return;
    ready_.push_back(std::move(task));
  }
  cv_.NotifyOne();
}

void StreamPump::PostAfter(std::chrono::steady_clock::duration delay, Task task) {
  {
    MutexLock lock(mu_);
    if (stop_) return;
    timers_.emplace(std::chrono::steady_clock::now() + delay, std::move(task));
  }
  // A sleeping thread may be waiting for a later timer than this one.
  cv_.NotifyOne();
}

std::uint64_t StreamPump::AddStopWaker(Task wake) {
  MutexLock lock(mu_);
  const std::uint64_t id = next_waker_++;
  wakers_.emplace(id, std::move(wake));
  return id;
}

void StreamPump::RemoveStopWaker(std::uint64_t id) {
  MutexLock lock(mu_);
  wakers_.erase(id);
}

void StreamPump::WakeAll() {
  std::vector<Task> wakers;
  {
    MutexLock lock(mu_);
    for (auto& [id, wake] : wakers_) wakers.push_back(wake);
  }
  for (Task& wake : wakers) wake();
}

void StreamPump::Stop() {
  {
    MutexLock lock(mu_);
    if (stop_) return;
    stop_ = true;
    timers_.clear();
  }
  cv_.NotifyAll();
  for (std::thread& t : threads_) t.join();
}

void StreamPump::Run() {
  MutexLock lock(mu_);
  for (;;) {
    // Timers that are due join the ready tasks, in their order.
    const auto now = std::chrono::steady_clock::now();
    while (!timers_.empty() && timers_.begin()->first <= now) {
      ready_.push_back(std::move(timers_.begin()->second));
      timers_.erase(timers_.begin());
    }
    if (!ready_.empty()) {
      Task task = std::move(ready_.front());
      ready_.pop_front();
      lock.Unlock();
      task();
      task = nullptr;  // what it held goes with it, outside the lock
      lock.Lock();
      continue;
    }
    if (stop_) return;
    if (timers_.empty()) {
      cv_.Wait(mu_);
    } else {
      cv_.WaitFor(mu_, timers_.begin()->first - now);
    }
  }
}

}  // namespace brdf::daemon
