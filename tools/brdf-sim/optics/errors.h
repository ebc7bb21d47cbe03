// The rig's known errors, which brdf-sim adds to what the meter reads so that the daemon's
// uncertainty budget can be checked against a truth (docs/simulator-errors.md). Each is off by
// default (brdf-sim then reads exactly as it always has) and each draws from its own random stream
// derived from the run's seed (--seed), so that a run is reproducible and switching one source
// on does not change the draws of another, nor the detector's shot and read noise
// (optics/optics.h).
//
//   gain noise        the meter's gain varies from one measurement to the next: all bands of a
//                     measurement are multiplied by 1 + gain_noise · z
//   lamp drift        the lamp's output changes while the meter works, linearly
//                     (lamp_drift_per_hour) and as a random walk (lamp_wander_per_sqrt_hour);
//                     the lamp's clock is the simulated time of the measurements made so far
//   white error       the white standard's true reflectance differs from its nominal one by a
//                     factor 1 + white_error · z, drawn once per run (one run = one session)
//   pose jitter       each axis stands off its reported position by pose_jitter_deg · z, drawn
//                     anew for every measurement
//   wavelength shift  the meter's band at λ measures λ + shift: a fixed wavelength_shift_nm plus
//                     a draw of wavelength_shift_sigma_nm · z, once per run
//   stray light       a fraction stray_light of the lamp's light reaches the detector by other
//                     paths (as if from a white diffuser at normal incidence) whenever the lamp
//                     shines: in sample and white readings, not in a dark one
// (z: a standard normal draw.)
#pragma once

#include <cstdint>
#include <mutex>
#include <random>

#include "core/pose.h"

namespace brdf::sim {

struct ErrorSources {
  double gain_noise = 0;
  double lamp_drift_per_hour = 0;
  double lamp_wander_per_sqrt_hour = 0;
  double white_error = 0;
  double pose_jitter_deg = 0;
  double wavelength_shift_nm = 0;
  double wavelength_shift_sigma_nm = 0;
  double stray_light = 0;
};

// The errors of one run: what was drawn once, and the state that evolves measurement by
// measurement. Thread-safe.
class RigErrors {
 public:
  RigErrors(const ErrorSources& sources, std::uint64_t seed);

  const ErrorSources& sources() const { return sources_; }
  // The white standard's true reflectance over its nominal one (1 without a white error).
  double white_factor() const { return white_factor_; }
  // How far the meter's wavelength scale is off, nm (0 without a shift).
  double wavelength_shift_nm() const { return wavelength_shift_nm_; }

  // The lamp's output now relative to the start of the run (1 without drift).
  double LampFactor() const;
  // The lamp has burned `seconds` more (simulated).
  void AdvanceLamp(double seconds);
  // Where the axes really are when the stage reports `reported` (the same without jitter).
  Pose TruePose(const Pose& reported);
  // The meter's gain for the next measurement (1 without gain noise).
  double NextGain();

 private:
  const ErrorSources sources_;
  double white_factor_ = 1;
  double wavelength_shift_nm_ = 0;

  mutable std::mutex mu_;  // guards what follows
  double lamp_hours_ = 0;
  double lamp_wander_ = 0;
  std::mt19937_64 lamp_rng_, pose_rng_, gain_rng_;
};

}  // namespace brdf::sim
