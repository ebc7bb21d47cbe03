#include "core/material/diffuse_lobes.h"

#include <algorithm>
#include <cmath>
#include <numbers>

namespace brdf::material {

void LambertLobe::AddTo(const DirectionPair&, std::span<const double> nm,
                        std::span<double> out) const {
  for (std::size_t k = 0; k < nm.size(); ++k) out[k] += albedo_.At(nm[k]) / std::numbers::pi;
}

OrenNayarLobe::OrenNayarLobe(SpectralValue albedo, double sigma_deg) : albedo_(std::move(albedo)) {
  const double sigma = sigma_deg * std::numbers::pi / 180.0;
  const double s2 = sigma * sigma;
  a_ = 1.0 - 0.5 * s2 / (s2 + 0.33);
  b_ = 0.45 * s2 / (s2 + 0.09);
}

double OrenNayarLobe::AngularFactor(const DirectionPair& d) const {
  // cos(φi − φo) from the directions' projections on the surface; 0 when either is the normal
  // (its azimuth is undefined, and sin β or tan β is 0 there anyway).
  const double pi_len = std::hypot(d.wi.x, d.wi.y), po_len = std::hypot(d.wo.x, d.wo.y);
  if (b_ == 0.0 || pi_len == 0.0 || po_len == 0.0) return a_;
  const double cos_dphi = (d.wi.x * d.wo.x + d.wi.y * d.wo.y) / (pi_len * po_len);
  if (cos_dphi <= 0.0) return a_;
  // α is the larger polar angle (the smaller cosine), β the smaller one.
  const double cos_alpha = std::clamp(std::min(d.cos_i(), d.cos_o()), 0.0, 1.0);
  const double cos_beta = std::clamp(std::max(d.cos_i(), d.cos_o()), 0.0, 1.0);
  if (cos_beta <= 0.0) return a_;
  const double sin_alpha = std::sqrt(1.0 - cos_alpha * cos_alpha);
  const double tan_beta = std::sqrt(1.0 - cos_beta * cos_beta) / cos_beta;
  return a_ + b_ * cos_dphi * sin_alpha * tan_beta;
}

void OrenNayarLobe::AddTo(const DirectionPair& d, std::span<const double> nm,
                          std::span<double> out) const {
  const double factor = AngularFactor(d) / std::numbers::pi;
  for (std::size_t k = 0; k < nm.size(); ++k) out[k] += albedo_.At(nm[k]) * factor;
}

}  // namespace brdf::material
