#include "core/uncertainty/meter_noise.h"

#include <algorithm>
#include <cmath>
#include <string>

namespace brdf::uncertainty {

Status CheckMeterNoiseModel(const MeterNoiseModel& m) {
  auto bad = [](const char* field, const char* rule) {
    return InvalidArgument(std::string("meter noise model: ") + field + " must be " + rule);
  };
  if (!std::isfinite(m.full_scale) || m.full_scale <= 0) return bad("full_scale", "> 0");
  if (!std::isfinite(m.full_well_counts) || m.full_well_counts <= 0) {
    return bad("full_well_counts", "> 0");
  }
  if (!std::isfinite(m.read_noise_counts) || m.read_noise_counts < 0) {
    return bad("read_noise_counts", "≥ 0");
  }
  if (!std::isfinite(m.adaptive_fill) || m.adaptive_fill <= 0) return bad("adaptive_fill", "> 0");
  if (!std::isfinite(m.gain_repeatability) || m.gain_repeatability < 0) {
    return bad("gain_repeatability", "≥ 0");
  }
  if (m.min_integration_ms <= 0 || m.max_integration_ms < m.min_integration_ms) {
    return bad("the integration range", "0 < min ≤ max (ms)");
  }
  return Status::Ok();
}

double IntegrationSeconds(const std::vector<double>& radiance, int integration_ms,
                          const MeterNoiseModel& model) {
  if (integration_ms > 0) return integration_ms / 1000.0;
  double peak = 0;
  for (double v : radiance) peak = std::max(peak, v);
  const double lo = model.min_integration_ms / 1000.0;
  const double hi = model.max_integration_ms / 1000.0;
  if (peak <= 0) return hi;
  return std::clamp(model.adaptive_fill * model.full_scale / peak, lo, hi);
}

Result<std::vector<double>> SignalUncertainty(const std::vector<double>& radiance,
                                              int integration_ms, int averages,
                                              const MeterNoiseModel& model) {
  if (Status s = CheckMeterNoiseModel(model); !s.ok()) return s;
  if (averages < 1) {
    return InvalidArgument("averages must be ≥ 1, got " + std::to_string(averages));
  }
  if (integration_ms < 0) {
    return InvalidArgument("integration_ms must be ≥ 0 (0: adaptive), got " +
                           std::to_string(integration_ms));
  }
  for (std::size_t b = 0; b < radiance.size(); ++b) {
    if (!std::isfinite(radiance[b])) {
      return InvalidArgument("band " + std::to_string(b) + " of the radiance is not finite");
    }
  }
  const double t = IntegrationSeconds(radiance, integration_ms, model);
  const double counts_per_radiance = t / model.full_scale * model.full_well_counts;
  const double r2 = model.read_noise_counts * model.read_noise_counts;
  std::vector<double> u(radiance.size());
  for (std::size_t b = 0; b < radiance.size(); ++b) {
    const double counts = std::max(radiance[b], 0.0) * counts_per_radiance;
    const double sigma = std::sqrt(counts + r2) / counts_per_radiance / std::sqrt(averages);
    const double gain = model.gain_repeatability * radiance[b];
    u[b] = std::sqrt(sigma * sigma + gain * gain);
  }
  return u;
}

}  // namespace brdf::uncertainty
