// What a plan costs: how many steps and readings, how often the operator must act, how long it
// should take, and how long it must take at the least (core/plan/timing.h has the model).
#pragma once

#include <span>

#include "core/plan/plan_settings.h"
#include "core/plan/rig_description.h"
#include "core/plan/step.h"

namespace brdf::plan {

struct PlanSummary {
  int step_count = 0;
  int sample_readings = 0;
  int reference_readings = 0;
  int dark_readings = 0;
  int operator_interventions = 0;  // prompts
  double estimated_duration_s = 0;
  // Sum over steps of the time that cannot overlap: integration, data transfer and motion,
  // each counted once (a move's motion hides behind the previous reading's transfer). No
  // operator time. See timing.h.
  double physical_lower_bound_s = 0;
};

PlanSummary SummarizeSteps(std::span<const Step> steps, const RigDescription& rig,
                           const MeasurementChoice& measurement);

}  // namespace brdf::plan
