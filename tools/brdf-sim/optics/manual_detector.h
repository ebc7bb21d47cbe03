// A rig without a motorized detector arm: the operator places the detector by hand, so the stage
// has no δ axis and the optics must take δ from somewhere else. This pose source passes the
// holder's α, β, γ through from the stage and reports the detector where the operator put it
// (brdf-sim --no-detector-arm --manual-delta D).
#pragma once

#include <atomic>

#include "tools/brdf-sim/sim_shared.h"

namespace brdf::sim {

class ManualDetectorPose final : public StagePoseSource {
 public:
  // `holder` must outlive this object.
  ManualDetectorPose(const StagePoseSource& holder, double delta_deg)
      : holder_(holder), delta_deg_(delta_deg) {}

  Pose LivePose() const override {
    Pose p = holder_.LivePose();
    p.delta = delta_deg_.load(std::memory_order_relaxed);
    return p;
  }

  // The operator moves the detector.
  void set_delta(double delta_deg) { delta_deg_.store(delta_deg, std::memory_order_relaxed); }
  double delta() const { return delta_deg_.load(std::memory_order_relaxed); }

 private:
  const StagePoseSource& holder_;
  std::atomic<double> delta_deg_;
};

}  // namespace brdf::sim
