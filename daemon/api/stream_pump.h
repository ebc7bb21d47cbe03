// StreamPump: the few threads that serve the long-lived streams (WatchSession, StreamReadings;
// issue 40) on gRPC's callback API, so that a stream waiting for its next event or reading holds
// no thread. Before, each such stream held a thread of gRPC's synchronous pool (its stack, its
// share of glibc's arenas) for as long as it stayed open: 700 waiting streams, 700 threads.
//
// A stream is a PumpedStream (pumped_stream.h): its body is stepped on the pump's threads when
// something may have changed (an event or a commit woke it, its write completed, its client
// cancelled, its idle wait passed, the server is stopping); a step writes one message or finds
// nothing to do and returns. The pump's threads run at nice 10, as the synchronous pool's stream
// threads did (rpc/thread_priority.h): below the control plane and Interpolate's loop.
#pragma once

#include <chrono>
#include <cstdint>
#include <deque>
#include <functional>
#include <map>
#include <thread>
#include <vector>

#include "core/mutex.h"

namespace brdf::daemon {

class StreamPump {
 public:
  using Task = std::function<void()>;

  // Starts `threads` (at least 1) threads named "stream-pump".
  explicit StreamPump(int threads);
  // Runs what is queued (not the timers), then joins the threads.
  ~StreamPump();
  StreamPump(const StreamPump&) = delete;
  StreamPump& operator=(const StreamPump&) = delete;

  // Runs `task` on a pump thread soon. Tasks must not block for long (a store page at most).
  void Post(Task task);
  // Runs `task` on a pump thread once `delay` has passed (dropped, not run, at Stop).
  void PostAfter(std::chrono::steady_clock::duration delay, Task task);

  // A stream's way to be woken by WakeAll (the server is stopping): registered while it lasts.
  std::uint64_t AddStopWaker(Task wake);
  void RemoveStopWaker(std::uint64_t id);
  // Calls every registered waker (on the calling thread; each only posts a step).
  void WakeAll();

  // Runs what is queued, drops the timers and joins the threads. Idempotent.
  void Stop();

  int threads() const { return static_cast<int>(threads_.size()); }

 private:
  void Run();

  Mutex mu_;
  CondVar cv_;
  bool stop_ GUARDED_BY(mu_) = false;
  std::deque<Task> ready_ GUARDED_BY(mu_);
  std::multimap<std::chrono::steady_clock::time_point, Task> timers_ GUARDED_BY(mu_);
  std::uint64_t next_waker_ GUARDED_BY(mu_) = 1;
  std::map<std::uint64_t, Task> wakers_ GUARDED_BY(mu_);
  std::vector<std::thread> threads_;
};

}  // namespace brdf::daemon
