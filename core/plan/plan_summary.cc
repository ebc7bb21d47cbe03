#include "core/plan/plan_summary.h"

#include "core/plan/timing.h"

namespace brdf::plan {

PlanSummary SummarizeSteps(std::span<const Step> steps, const RigDescription& rig,
                           const MeasurementChoice& measurement) {
  PlanSummary s;
  StepTimer timer(rig, measurement);
  for (const Step& step : steps) {
    timer.Advance(step);
    ++s.step_count;
    switch (step.kind) {
      case v1::STEP_KIND_SAMPLE:
        ++s.sample_readings;
        break;
      case v1::STEP_KIND_REFERENCE:
        ++s.reference_readings;
        break;
      case v1::STEP_KIND_DARK:
        ++s.dark_readings;
        break;
      case v1::STEP_KIND_PROMPT:
        ++s.operator_interventions;
        break;
      default:
        break;
    }
  }
  s.estimated_duration_s = timer.elapsed_estimate_s();
  s.physical_lower_bound_s = timer.elapsed_lower_bound_s();
  return s;
}

}  // namespace brdf::plan
