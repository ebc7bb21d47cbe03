// What one more sample reading costs a round, in rig time and operator prompts, by the plan's
// own timing model (core/plan/timing.h) and its own policies: the move and the reading (StepTimer
// over a move and a sample step, the move overlapping the previous reading's transfer); a change
// of δ adds what the plan expander puts between two readings at different δ (the relocation
// prompt, or the arm's move, and under reference.perDetectorPosition the reference block with
// its prompts and, with dark.withEachReference, the dark), measured once by expanding a two-pose
// pose list with the plan's policies; a change of γ on a manual dial adds its prompt. The
// reference rules by count or by minutes are not charged per pose (the round's steps, expanded
// as a pose list, carry them exactly). In a sample-fixed plan every pose is a prompt: each costs
// the same, the relocation prompt and what follows it (FixedPoseCost), wherever it goes. It also
// says which poses the rig can take at all (CanReach: the rig's travel and the adaptive plan's
// region), for candidates a round makes up.
#pragma once

#include <optional>
#include <span>

#include "brdf/v1/plan.pb.h"
#include "core/adaptive/adaptive_spec.h"
#include "core/plan/plan_settings.h"
#include "core/plan/rig_description.h"
#include "core/pose.h"

namespace brdf::adaptive {

struct PoseCost {
  double seconds = 0;
  int prompts = 0;
  PoseCost& operator+=(const PoseCost& other) {
    seconds += other.seconds;
    prompts += other.prompts;
    return *this;
  }
};

// What the plan expander puts after the first of `probe`'s two sample readings (a two-pose plan
// made from `plan` to measure a cost): the steps up to and including the second reading
// (`through_second`), or else those before the step that precedes it (the move to the second
// pose), by the timing model for `rig` and `plan`'s measurement. Zero when `probe` does not expand
// to two sample readings.
PoseCost CostAfterFirstReading(const v1::Plan& probe, const v1::Plan& plan,
                               const plan::RigDescription& rig, bool through_second);

class RoundCost {
 public:
  // `plan` gives the reference, dark and measurement policies (of its method only whether it is
  // sample-fixed, plan::SampleFixedMethod); `rig`
  // the timing and which axes are manual. Times are for real devices (time scale 1): budgets
  // are in a real rig's time.
  RoundCost(const v1::Plan& plan, const plan::RigDescription& rig);

  // From a reading at `from` to a reading at `to` (model angles).
  PoseCost Step(const Pose& from, const Pose& to) const;
  // Step() without what a change of δ or of a manual γ adds: the move and the reading alone.
  double MoveAndReadSeconds(const Pose& from, const Pose& to) const;
  // The readings `poses` in order, the rig starting after a reading at `from`.
  PoseCost Sequence(const Pose& from, std::span<const Pose> poses) const;
  // What a change of δ adds to a reading (see above).
  const PoseCost& delta_change() const { return delta_change_; }
  // True for a sample-fixed plan (plan::SampleFixedMethod): every pose a prompt, set by hand.
  bool sample_fixed() const { return fixed_pose_.has_value(); }
  // True when the pose (model angles) is within the rig's travel and both its directions lie in
  // the plan's adaptive region (the default region for a plan of another method):
  // seed_design.h's Reachable, as for the candidates.
  bool CanReach(const Pose& pose) const;

 private:
  plan::RigDescription rig_;
  Region region_;
  plan::MeasurementChoice measurement_;
  PoseCost delta_change_;
  // A sample-fixed plan (plan::SampleFixedMethod): every pose costs this, wherever it goes
  // (sample_fixed_design.h: FixedPoseCost).
  std::optional<PoseCost> fixed_pose_;
};

}  // namespace brdf::adaptive
