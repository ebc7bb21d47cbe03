// What the plan code needs to know about the rig: which axes are motorized, how far and how
// fast they go, and how long the meter and the operator take. The daemon fills it from its
// configuration (daemon/config/config.h: ToRigDescription); tests and tools build it by hand.
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

// The integration time the meter is expected to choose, by kind of reading, when the plan says
// adaptive (seconds). Adaptive integration aims the brightest band at a fill of the detector, so
// the time follows the light: the white standard is bright (short), a sample is dimmer and varies
// with the pose, a dark reading (lamp shuttered) never fills the detector and runs to the meter's
// longest time (the PR-650's 6 s). Defaults: [meter] adaptive_*_ms (daemon/config/config.h).
struct AdaptiveIntegration {
  double reference_s = 2.0;
  double dark_s = 6.0;
  double sample_s = 2.0;
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
  double meter_transfer_s = 1.8;  // D5 spectrum report, ~1,730 bytes at 9600 baud
  // Expected integration by kind of reading when the plan says adaptive ([meter] adaptive_*_ms).
  AdaptiveIntegration adaptive_integration;
  double min_integration_s = 0.010;  // the meter's shortest integration (lower bound)
  // The meter's own time per reading beyond integration and transfer (shutter, dark scan,
  // processing), counted once per reading whatever the averages ([meter] overhead_ms).
  double reading_overhead_s = 0.3;
  // The meter's own time per measurement beyond the integration (shutter, dark and processing
  // inside M0), which nothing can overlap: part of the physical lower bound. 0 unless known for
  // the instrument (pr650.md gives none; brdf-sim models 1.0 s: [optics.detector] overhead_s).
  double meter_measure_overhead_s = 0;
  double move_settle_s = 0.25;    // the stage's settling after the motion, per move
  double operator_action_s = 30;  // one manual action (a prompt) by the operator

  // The daemon's own waits (host time). Unlike everything above they do not shrink when the
  // rig runs faster (`time_scale`): at brdf-sim's time scale 32 they are a large part of a step.
  // Per reading: command pacing and the quiet gap that ends each reply (defaults: one M5
  // exchange at the default pacing_ms = 100 and quiet_gap_ms = 50).
  double reading_host_s = 0.15;
  // The part of reading_host_s after the meter holds the measurement (the last reply's quiet
  // gap; with M0 then D5 also D5's pacing): a pipelined move overlaps it with the transfer.
  double reading_host_after_s = 0.05;
  // The stage driver's in-position polling interval: a move is seen finished at the first poll
  // after it ends, so a move takes a whole number (>= 1) of polls. 0: seen at once.
  double stage_poll_s = 0.1;

  // The rig's devices run this many times faster than real ones (brdf-sim --time-scale): the
  // device times above are divided by it, host time and operator time are not. > 0; 1 = real.
  double time_scale = 1;
};

}  // namespace brdf::plan
