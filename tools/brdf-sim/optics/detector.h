// The PR-650's detector as the simulator models it: how full a given radiance fills it in a given
// integration time, the integration time adaptive mode picks, the quality code the light level
// earns, the noise of one reading, and how long a measurement takes.
//
// Units: radiance in W·m⁻²·sr⁻¹·nm⁻¹, integration in ms. "Fill" is the fraction of full scale the
// brightest band reaches: radiance · integration / full_scale.
#pragma once

#include "tools/brdf-sim/sim_shared.h"

namespace brdf::sim {

struct DetectorConfig {
  // Radiance × time (W·m⁻²·sr⁻¹·nm⁻¹·s) that fills the detector. With the default lamp the white
  // standard at normal incidence (brightest band ≈ 0.19 at 780 nm) fills it in about 200 ms.
  double full_scale = 0.04;
  // Adaptive integration aims the brightest band at this fill.
  double adaptive_fill = 0.5;
  // Below these fills the meter reports 18 (low light) and 10 (weak signal).
  double low_light_fill = 0.02;
  double weak_fill = 0.002;
  // Noise: shot noise of `full_well_counts` electrons at full scale, plus a read-noise floor.
  double full_well_counts = 2e5;
  double read_noise_counts = 20;
  // The meter's limits on integration time (S command: 10–6000 ms).
  int min_integration_ms = 10;
  int max_integration_ms = 6000;
  // Fixed cost of one measurement (shutter, dark scan, processing), simulated seconds.
  double overhead_s = 1.0;
};

// What the meter settles on for one measurement.
struct Exposure {
  int integration_ms = 0;
  double fill = 0;       // of the brightest band
  int quality_code = 0;  // 0, 10, 18 or 19 from the light level
};

class Detector {
 public:
  explicit Detector(DetectorConfig config = {}) : config_(config) {}

  // The integration time and quality code for a scene whose brightest band has `peak_radiance`.
  // setup.integration_ms == 0 picks the time adaptively (short for bright, long for dim), else the
  // requested time is used as given (clamped to the meter's range) and may overload (19).
  Exposure ChooseExposure(double peak_radiance, const MeterSetup& setup) const;

  // Quality code for a fill: 19 above full scale, 10 below weak_fill, 18 below low_light_fill.
  int QualityForFill(double fill) const;

  // Standard deviation of one reported band (already averaged over `averages` scans) for a true
  // radiance, in radiance units: sqrt(shot² + floor²), shot ∝ sqrt(signal).
  double NoiseSigma(double radiance, int integration_ms, int averages) const;

  // The radiance that just fills the detector in `integration_ms` (the meter clips there).
  double SaturationRadiance(int integration_ms) const;

  // Simulated seconds one measurement takes: integration × averages + overhead.
  double DurationSeconds(int integration_ms, int averages) const;

  const DetectorConfig& config() const { return config_; }

 private:
  DetectorConfig config_;
};

}  // namespace brdf::sim
