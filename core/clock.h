// The clock seam. Code that waits (drivers polling a stage, the executor pacing references, the
// simulator's motion model) asks a Clock instead of the OS, so tests can run on scaled or manual
// time and stay fast and deterministic.
#pragma once

#include <chrono>
#include <memory>

namespace brdf {

class CancelToken;

class Clock {
 public:
  using Duration = std::chrono::steady_clock::duration;
  using TimePoint = std::chrono::steady_clock::time_point;

  virtual ~Clock() = default;
  // Monotonic now.
  virtual TimePoint Now() const = 0;
  // Sleeps for `d`, returning early (false) if `cancel` is cancelled meanwhile. True if slept
  // fully.
  virtual bool SleepFor(Duration d, const CancelToken* cancel = nullptr) const = 0;

  // The process-wide real clock (std::chrono::steady_clock).
  static const Clock& Real();
};

}  // namespace brdf
