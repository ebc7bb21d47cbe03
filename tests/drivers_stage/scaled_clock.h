// A clock that runs `factor` times faster than real time, for driving the stage on the same
// scaled time as the simulator (brdf::sim::TimeScale) so that moves take milliseconds.
#pragma once

#include <chrono>
#include <thread>

#include "core/call_context.h"
#include "core/clock.h"

namespace brdf::testing {

class ScaledClock final : public Clock {
 public:
  explicit ScaledClock(double factor)
      : factor_(factor), origin_(std::chrono::steady_clock::now()) {}

  TimePoint Now() const override {
    const auto real = std::chrono::steady_clock::now() - origin_;
    return origin_ + std::chrono::duration_cast<Duration>(real * factor_);
  }
  bool SleepFor(Duration d, const CancelToken* cancel) const override {
    const auto real = std::chrono::duration_cast<Duration>(d / factor_);
    if (cancel == nullptr) {
      std::this_thread::sleep_for(real);
      return true;
    }
    return !cancel->WaitFor(real);
  }
  double factor() const { return factor_; }

 private:
  double factor_;
  TimePoint origin_;
};

}  // namespace brdf::testing
