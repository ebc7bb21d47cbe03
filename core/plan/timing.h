// How long steps take: an estimate (what the operator should expect) and a physical lower
// bound (what no scheduling can beat). Used for the plan summary, the "every M minutes"
// reference rule, and the executor's ETA.
//
// The model, per step (times in seconds, RigDescription's parameters). Device times (the meter's
// and the stage's) are divided by rig.time_scale (written "/ k" below); the daemon's own waits
// (host time) and the operator's time are not, so a simulated rig at time scale 32 is estimated
// as it runs, not as a 32nd of a real one.
//   reading (REFERENCE, DARK, SAMPLE):
//     estimate    = (reading_overhead_s + integration · averages + meter_transfer_s) / k
//                   + reading_host_s
//     lower bound = (integration_min · averages + meter_measure_overhead_s + meter_transfer_s) / k
//     where integration is integration_ms / 1000, or when adaptive the time expected for the
//     reading's kind (adaptive_integration.reference_s, .dark_s or .sample_s: the meter picks it
//     from the light, so a dark reading takes far longer than a reference); for the lower bound,
//     min_integration_s (the meter's shortest) when adaptive. reading_overhead_s counts once per
//     reading, however many averages.
//   move: the motorized axes (α, β, and γ / δ when present) move at the same time, so
//     motion = max over moving axes of |Δ reading| / speed_deg_s / k.
//     estimate    = motion + move_settle_s / k, rounded up to a whole number (>= 1) of
//                   stage_poll_s (the driver sees the end at a poll); 0 when nothing moves
//     lower bound = motion
//     A move right after a reading overlaps that reading's data transfer (the executor starts
//     the move once the meter has measured, while the spectrum comes down the serial line), so
//     that is taken off: the estimate loses meter_transfer_s / k + reading_host_after_s, the
//     lower bound meter_transfer_s / k (never below 0).
//   prompt: estimate = operator_action_s; lower bound = 0 (operator time is not physics).
// The lower bound therefore sums exactly what cannot overlap: integration and the meter's own
// measuring time, data transfer not hidden behind motion, and motion not hidden behind a
// transfer. The rig starts at pose 0. It is the bound for a pipelining executor; without
// pipelining, PlanLowerBound(..., /*pipelined=*/false) adds the hidden part back (what a
// sequential executor cannot beat), which is how the bench compares the two.
#pragma once

#include <span>
#include <vector>

#include "core/plan/plan_settings.h"
#include "core/plan/rig_description.h"
#include "core/plan/step.h"

namespace brdf::plan {

struct StepTime {
  double estimate_s = 0;
  double lower_bound_s = 0;
};

// A running clock over a list of steps, fed one step at a time in order.
class StepTimer {
 public:
  StepTimer(const RigDescription& rig, const MeasurementChoice& measurement);

  // The time of `step`, given the steps fed before it; advances the clock.
  StepTime Advance(const Step& step);

  double elapsed_estimate_s() const { return elapsed_.estimate_s; }
  double elapsed_lower_bound_s() const { return elapsed_.lower_bound_s; }

 private:
  double MotionSeconds(const Pose& from, const Pose& to) const;

  RigDescription rig_;
  MeasurementChoice measurement_;
  Pose stage_;                  // where the motorized axes are
  bool after_reading_ = false;  // the previous step was a reading
  double scale_ = 1;            // rig_.time_scale, 1 when not positive
  StepTime elapsed_;
};

// The physical lower bound of a whole list of steps, in seconds: the sum of StepTimer's
// lower_bound_s when `pipelined`; else every move's full motion time (a move that waits for the
// previous transfer to finish hides nothing behind it).
double PlanLowerBound(std::span<const Step> steps, const RigDescription& rig,
                      const MeasurementChoice& measurement, bool pipelined = true);

// The time of every step of a list (StepTimer over the list).
std::vector<StepTime> EstimateSteps(std::span<const Step> steps, const RigDescription& rig,
                                    const MeasurementChoice& measurement);

}  // namespace brdf::plan
