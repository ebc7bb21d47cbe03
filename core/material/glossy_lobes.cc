#include "core/material/glossy_lobes.h"

#include <algorithm>
#include <cmath>
#include <numbers>

namespace brdf::material {
namespace {

// Below this cosine a direction counts as grazing: the microfacet lobe's 1/cos factors are
// balanced by G2 → 0 only in the limit, so exactly there the lobe gives 0.
constexpr double kGrazingCos = 1e-12;

}  // namespace

MicrofacetLobe::MicrofacetLobe(FacetSlopes slopes, Roughness alpha, Fresnel fresnel,
                               SpectralValue weight)
    : slopes_(slopes), alpha_(alpha), fresnel_(std::move(fresnel)), weight_(std::move(weight)) {}

std::string_view MicrofacetLobe::type() const {
  return slopes_ == FacetSlopes::kGgx ? "ggx" : "beckmann";
}

void MicrofacetLobe::AddTo(const DirectionPair& d, std::span<const double> nm,
                           std::span<double> out) const {
  if (d.cos_i() <= kGrazingCos || d.cos_o() <= kGrazingCos) return;
  Vec3 h;
  if (!HalfVector(d, h)) return;
  const double geometric = FacetDensity(slopes_, alpha_, h) * SmithShadowing(slopes_, alpha_, d) /
                           (4.0 * d.cos_i() * d.cos_o());
  if (!(geometric > 0.0)) return;
  const double cos_d = Dot(d.wi, h);
  for (std::size_t k = 0; k < nm.size(); ++k) {
    out[k] += weight_.At(nm[k]) * fresnel_.Reflectance(cos_d, nm[k]) * geometric;
  }
}

BlinnPhongLobe::BlinnPhongLobe(SpectralValue weight, double exponent_x, double exponent_y)
    : weight_(std::move(weight)), exponent_x_(exponent_x), exponent_y_(exponent_y) {}

void BlinnPhongLobe::AddTo(const DirectionPair& d, std::span<const double> nm,
                           std::span<double> out) const {
  // The same operations in the same order as core/analytic_brdf.cc's SpecularBrdf, so that the
  // built-in samples agree with it to the bit.
  Vec3 h;
  if (!HalfVector(d, h)) return;
  const double hz = std::clamp(h.z, 0.0, 1.0);
  const double tangential2 = h.x * h.x + h.y * h.y;
  const bool anisotropic = exponent_x_ != exponent_y_;
  double exponent = exponent_x_;
  // At h = n the azimuth of h is undefined but hz^e = 1 for any e.
  if (anisotropic && tangential2 > 0.0) {
    exponent = (exponent_x_ * h.x * h.x + exponent_y_ * h.y * h.y) / tangential2;
  }
  const double norm =
      anisotropic ? std::sqrt((exponent_x_ + 8.0) * (exponent_y_ + 8.0)) : exponent_x_ + 8.0;
  const double lobe = std::pow(hz, exponent);
  for (std::size_t k = 0; k < nm.size(); ++k) {
    const double w = weight_.At(nm[k]);
    if (w == 0.0) continue;
    out[k] += w * norm / (8.0 * std::numbers::pi) * lobe;
  }
}

RetroLobe::RetroLobe(SpectralValue weight, double exponent)
    : weight_(std::move(weight)), exponent_(exponent) {}

void RetroLobe::AddTo(const DirectionPair& d, std::span<const double> nm,
                      std::span<double> out) const {
  const double c = Dot(d.wi, d.wo);
  if (c <= 0.0) return;
  const double lobe = (exponent_ + 1.0) / (2.0 * std::numbers::pi) * std::pow(c, exponent_);
  for (std::size_t k = 0; k < nm.size(); ++k) out[k] += weight_.At(nm[k]) * lobe;
}

}  // namespace brdf::material
