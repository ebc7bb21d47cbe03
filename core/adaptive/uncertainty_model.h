// What the round chooser asks of an uncertainty model: from the readings so far, how much
// uncertainty is left over the region, and how much a reading at a candidate direction would
// take away. The model behind it (the measurement budgets blended with the interpolation term,
// docs/uncertainty.md, once issue 37 has calibrated that term) is not part of core/adaptive;
// tests use a simple stand-in (tests/adaptive).
//
// Two steps, so that the chooser stays deterministic and cheap: Map() is a pure function of the
// readings (same readings, same order: same answers), built once per round; the map then takes
// the round's picks one by one (Assume) so that later picks of the same batch are predicted
// with the earlier ones in place and do not pile onto one spot.
#pragma once

#include <memory>
#include <span>

#include "core/pose.h"

namespace brdf::adaptive {

// A sample reading as the planner sees it: where it was taken and what it gave.
struct ReadingSoFar {
  Pose pose;              // model angles
  Directions directions;  // lamp and detector in the sample's frame
  double brdf = 0;        // a scalar summary of its BRDF (e.g. over the visible bands), sr⁻¹
  double relative_uncertainty = 0;  // its relative standard uncertainty (k = 1)
};

class UncertaintyMap {
 public:
  virtual ~UncertaintyMap() = default;
  // The uncertainty left over the region, integrated with the weight cos θi · cos θo, in the
  // target's unit (relative, docs/adaptive.md): what the stop rule compares with the target.
  // Counts the readings the map was built from and every Assume()d pick.
  virtual double Remaining() const = 0;
  // The predicted fall of Remaining() if one more reading were taken at `candidate` (after the
  // Assume()d picks). ≥ 0; 0 where a reading would teach nothing.
  virtual double PredictedGain(const Directions& candidate) const = 0;
  // Counts a chosen, not yet measured reading at `chosen` as its predicted effect.
  virtual void Assume(const Directions& chosen) = 0;
};

class UncertaintyModel {
 public:
  virtual ~UncertaintyModel() = default;
  // The map for these readings; never null.
  virtual std::unique_ptr<UncertaintyMap> Map(std::span<const ReadingSoFar> readings) const = 0;
};

}  // namespace brdf::adaptive
