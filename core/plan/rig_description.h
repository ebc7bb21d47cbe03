// What the plan code needs to know about the rig: which axes are motorized, how far and how
// fast they go, and how long the meter and the operator take. The daemon fills it from its
// configuration (daemon/config.h: ToRigDescription); tests and tools build it by hand.
// Defaults describe the paper's rig: α/β stages, a manual detector and γ dial, a PR-650 at
// 9600 baud.
#pragma once

#include "core/geometry.h"

namespace brdf::plan {

// Travel and speed of one axis, in stage readings (degrees).
struct AxisTravel {
  double min_deg = -180;
  double max_deg = 180;
  double speed_deg_s = 10;  // > 0; used for motion time estimates
  bool Contains(double reading_deg) const {
    return reading_deg >= min_deg - 1e-9 && reading_deg <= max_deg + 1e-9;
  }
};

struct RigDescription {
  // A motorized γ axis. Without it γ is a dial the operator turns (a prompt per change).
  bool has_gamma_axis = false;
  // A motorized detector arm (δ axis). Without it the operator relocates the detector.
  bool has_detector_arm = false;

  // Travel limits and speeds. δ's limits apply to manual detectors too (where it can be put).
  AxisTravel alpha{0, 90, 10};
  AxisTravel beta{-180, 180, 20};
  AxisTravel gamma{-180, 180, 20};
  AxisTravel delta{0, 180, 10};

  // Stage readings ↔ geometry.md's model angles (zero offsets, signs). Plans are written in
  // model angles; steps carry stage readings.
  HolderConvention convention;

  // Timing model (core/plan/timing.h). Seconds.
  double meter_transfer_s = 1.8;        // D5 spectrum report, ~1,730 bytes at 9600 baud
  double adaptive_integration_s = 2.0;  // expected integration when the plan says adaptive
  double min_integration_s = 0.010;     // the meter's shortest integration (lower bound)
  double reading_overhead_s = 0.5;      // command pacing and meter processing per reading
  // The meter's own time per measurement beyond the integration (shutter, dark and processing
  // inside M0), which nothing can overlap: part of the physical lower bound. 0 unless known for
  // the instrument (pr650.md gives none; brdf-sim models 1.0 s: [optics.detector] overhead_s).
  double meter_measure_overhead_s = 0;
  double move_settle_s = 0.25;    // in-position polling and settling per move
  double operator_action_s = 30;  // one manual action (a prompt) by the operator
};

}  // namespace brdf::plan
