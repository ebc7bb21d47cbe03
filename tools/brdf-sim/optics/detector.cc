#include "tools/brdf-sim/optics/detector.h"

#include <algorithm>
#include <cmath>

namespace brdf::sim {

int Detector::QualityForFill(double fill) const {
  if (fill > 1.0) return 19;
  if (fill < config_.weak_fill) return 10;
  if (fill < config_.low_light_fill) return 18;
  return 0;
}

Exposure Detector::ChooseExposure(double peak_radiance, const MeterSetup& setup) const {
  const double peak = std::max(peak_radiance, 0.0);
  Exposure e;
  if (setup.integration_ms > 0) {
    e.integration_ms =
        std::clamp(setup.integration_ms, config_.min_integration_ms, config_.max_integration_ms);
  } else if (peak <= 0) {
    e.integration_ms = config_.max_integration_ms;
  } else {
    // Time that brings the brightest band to the target fill, within the meter's range.
    const double ms = config_.adaptive_fill * config_.full_scale / peak * 1000.0;
    e.integration_ms =
        static_cast<int>(std::clamp(std::round(ms), static_cast<double>(config_.min_integration_ms),
                                    static_cast<double>(config_.max_integration_ms)));
  }
  e.fill = peak * e.integration_ms / 1000.0 / config_.full_scale;
  e.quality_code = QualityForFill(e.fill);
  return e;
}

double Detector::NoiseSigma(double radiance, int integration_ms, int averages) const {
  const double t = std::max(integration_ms, 1) / 1000.0;
  const double counts_per_radiance = t / config_.full_scale * config_.full_well_counts;
  const double counts = std::max(radiance, 0.0) * counts_per_radiance;
  const double sigma_counts =
      std::sqrt(counts + config_.read_noise_counts * config_.read_noise_counts);
  return sigma_counts / counts_per_radiance / std::sqrt(std::max(averages, 1));
}

double Detector::SaturationRadiance(int integration_ms) const {
  return config_.full_scale / (std::max(integration_ms, 1) / 1000.0);
}

double Detector::DurationSeconds(int integration_ms, int averages) const {
  return integration_ms / 1000.0 * std::max(averages, 1) + config_.overhead_s;
}

}  // namespace brdf::sim
