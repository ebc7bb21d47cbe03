// The expansion of a checked plan into steps (the work behind ExpandPlan, see
// core/plan/analyze_plan.h for the public entry points and the full order of steps).
//
// Precondition: CheckPlanFields found no problem (every number finite and in range, counts
// bounded). The problems only the expansion can see are added to `sink`: poses of the grid
// beyond the β (or γ) travel, reference poses beyond the α/β travel or too close to grazing.
// Stops adding steps after kMaxSteps + 1; the caller reports the overflow.
#pragma once

#include <cstdint>
#include <span>
#include <vector>

#include "brdf/v1/plan.pb.h"
#include "core/plan/problem.h"
#include "core/plan/rig_description.h"
#include "core/plan/step.h"

namespace brdf::plan {

std::vector<Step> ExpandCheckedPlan(const v1::Plan& plan, const RigDescription& rig,
                                    ProblemSink& sink);

// Where an expansion continues from: the rig after steps already stored (an adaptive round is
// expanded after the steps before it, docs/adaptive.md).
struct ExpansionStart {
  Pose model;  // where the rig is, model angles (the last step's pose)
  bool have_reference = false;
  bool relocated_since_reference = false;  // the detector moved since the last reference
  std::uint32_t samples_since_reference = 0;
  double seconds_since_reference = 0;  // by the timing estimate
};

// The state after `steps` (stored steps, in order), by `plan`'s measurement settings and the
// rig's timing model. Pure.
ExpansionStart StartAfter(std::span<const Step> steps, const v1::Plan& plan,
                          const RigDescription& rig);

// `poses` (model angles) expanded as a pose list with `plan`'s policies (references, darks,
// relocation and dial prompts), continuing from `start`: the detector is relocated (the dial
// turned) only where a pose's δ (γ) differs from where the rig is, and a reference is added
// where the policies make one due counting from `start`. Steps are numbered from `first_index`.
// Precondition: `plan` passed CheckPlanFields and the poses are within the rig's travel.
std::vector<Step> ExpandPosesFrom(const v1::Plan& plan, const RigDescription& rig,
                                  const ExpansionStart& start, std::span<const Pose> poses,
                                  int first_index);

}  // namespace brdf::plan
