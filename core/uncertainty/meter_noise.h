// The meter's repeatability as brdfd models it (docs/uncertainty.md, "The meter's noise model"):
// per band, the detector's shot noise and read noise, reduced by the reading's averages, plus a
// relative responsivity wander between measurements that averaging does not reduce:
//   counts = L · t / F · N,   σ(L) = sqrt(counts + r²) · F / (t · N) / sqrt(averages),
//   u(L)²  = σ(L)² + (g · L)².
// The defaults are brdf-sim's detector (tools/brdf-sim/optics/detector.h): assumptions for a real
// PR-650, whose data sheet was not at hand. Pure: no I/O.
#pragma once

#include <vector>

#include "core/status.h"

namespace brdf::uncertainty {

struct MeterNoiseModel {
  // F: radiance × time that fills the detector, W·m⁻²·sr⁻¹·nm⁻¹·s.
  double full_scale = 0.04;
  // N: counts (electrons) at full scale.
  double full_well_counts = 2e5;
  // r: read noise, counts.
  double read_noise_counts = 20;
  // a: the fill adaptive integration aims the brightest band at.
  double adaptive_fill = 0.5;
  // g: relative responsivity wander between measurements (the same for every band).
  double gain_repeatability = 0;
  // The meter's range of integration times, ms (the PR-650's S command: 10–6000).
  int min_integration_ms = 10;
  int max_integration_ms = 6000;
};

// kInvalidArgument naming the field when a parameter is not finite, F, N or a is ≤ 0, r or g is
// negative, or the integration range is empty or not positive.
Status CheckMeterNoiseModel(const MeterNoiseModel& model);

// The integration time in seconds a reading was taken with: its own when integration_ms > 0,
// else the time adaptive mode picks for its brightest band (a · F / max L, within the meter's
// range; the longest when nothing is bright, as for a dark reading).
double IntegrationSeconds(const std::vector<double>& radiance, int integration_ms,
                          const MeterNoiseModel& model);

// u(L) per band for a reading's reported radiance (W·m⁻²·sr⁻¹·nm⁻¹). Negative values count as 0
// photons. Errors: averages < 1, integration_ms < 0, a non-finite value, a bad model.
Result<std::vector<double>> SignalUncertainty(const std::vector<double>& radiance,
                                              int integration_ms, int averages,
                                              const MeterNoiseModel& model);

}  // namespace brdf::uncertainty
