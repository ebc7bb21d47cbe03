#include "core/plan/timing.h"

#include <algorithm>
#include <cmath>

namespace brdf::plan {

StepTimer::StepTimer(const RigDescription& rig, const MeasurementChoice& measurement)
    : rig_(rig), measurement_(measurement), scale_(rig.time_scale > 0 ? rig.time_scale : 1) {}

namespace {

// `seconds` rounded up to a whole number (>= 1) of `poll` (unchanged when poll is 0).
double ToWholePolls(double seconds, double poll) {
  if (poll <= 0) return seconds;
  return std::max(1.0, std::ceil(seconds / poll - 1e-9)) * poll;
}

// The adaptive integration expected for a reading of `kind`.
double AdaptiveSeconds(const AdaptiveIntegration& adaptive, StepKind kind) {
  switch (kind) {
    case v1::STEP_KIND_REFERENCE:
      return adaptive.reference_s;
    case v1::STEP_KIND_DARK:
      return adaptive.dark_s;
    default:
      return adaptive.sample_s;
  }
}

}  // namespace

double StepTimer::MotionSeconds(const Pose& from, const Pose& to) const {
  auto axis = [](double a, double b, const AxisTravel& travel) {
    return travel.speed_deg_s > 0 ? std::fabs(b - a) / travel.speed_deg_s : 0.0;
  };
  double t = std::max(axis(from.alpha, to.alpha, rig_.alpha), axis(from.beta, to.beta, rig_.beta));
  if (rig_.has_gamma_axis) t = std::max(t, axis(from.gamma, to.gamma, rig_.gamma));
  if (rig_.has_detector_arm) t = std::max(t, axis(from.delta, to.delta, rig_.delta));
  return t;
}

StepTime StepTimer::Advance(const Step& step) {
  StepTime t;
  if (step.is_reading()) {
    const double averages = std::max<double>(1, measurement_.averages);
    const double integration = measurement_.adaptive()
                                   ? AdaptiveSeconds(rig_.adaptive_integration, step.kind)
                                   : measurement_.integration_ms / 1000.0;
    const double integration_min =
        measurement_.adaptive() ? rig_.min_integration_s : measurement_.integration_ms / 1000.0;
    t.estimate_s =
        (rig_.reading_overhead_s + integration * averages + rig_.meter_transfer_s) / scale_ +
        rig_.reading_host_s;
    t.lower_bound_s =
        (integration_min * averages + rig_.meter_measure_overhead_s + rig_.meter_transfer_s) /
        scale_;
    after_reading_ = true;
  } else if (step.kind == v1::STEP_KIND_MOVE) {
    const double motion = MotionSeconds(stage_, step.pose) / scale_;
    double estimate =
        motion > 0 ? ToWholePolls(motion + rig_.move_settle_s / scale_, rig_.stage_poll_s) : 0.0;
    double lower = motion;
    if (after_reading_) {
      const double transfer = rig_.meter_transfer_s / scale_;
      estimate = std::max(0.0, estimate - transfer - rig_.reading_host_after_s);
      lower = std::max(0.0, lower - transfer);
    }
    t = {estimate, lower};
    stage_ = step.pose;
    after_reading_ = false;
  } else {
    t.estimate_s = step.kind == v1::STEP_KIND_PROMPT ? rig_.operator_action_s : 0.0;
    after_reading_ = false;
  }
  elapsed_.estimate_s += t.estimate_s;
  elapsed_.lower_bound_s += t.lower_bound_s;
  return t;
}

double PlanLowerBound(std::span<const Step> steps, const RigDescription& rig,
                      const MeasurementChoice& measurement, bool pipelined) {
  StepTimer timer(rig, measurement);
  // Sequential: an empty pause between a reading and the move after it (a prompt's lower bound
  // is 0) stops the move from hiding the transfer.
  Step pause;
  pause.kind = v1::STEP_KIND_PROMPT;
  const Step* previous = nullptr;
  for (const Step& s : steps) {
    if (!pipelined && previous != nullptr && previous->is_reading() &&
        s.kind == v1::STEP_KIND_MOVE) {
      timer.Advance(pause);
    }
    timer.Advance(s);
    previous = &s;
  }
  return timer.elapsed_lower_bound_s();
}

std::vector<StepTime> EstimateSteps(std::span<const Step> steps, const RigDescription& rig,
                                    const MeasurementChoice& measurement) {
  StepTimer timer(rig, measurement);
  std::vector<StepTime> times;
  times.reserve(steps.size());
  for (const Step& s : steps) times.push_back(timer.Advance(s));
  return times;
}

}  // namespace brdf::plan
