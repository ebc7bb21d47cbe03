// Lobes of matte scattering, spread over the whole hemisphere.
//
//   Lambert       f = ρ(λ) / π: the ideal diffuse reflector of albedo ρ.
//   Oren–Nayar    the qualitative model of Oren & Nayar (1994) for a surface of Lambertian
//                 V-grooves whose slope angles have standard deviation σ:
//                   f = ρ(λ) / π · (A + B · max(0, cos(φi − φo)) · sin α · tan β),
//                   A = 1 − 0.5 σ² / (σ² + 0.33),  B = 0.45 σ² / (σ² + 0.09),
//                   α = max(θi, θo), β = min(θi, θo)   (σ in radians).
//                 σ = 0 is Lambert. Where both directions graze (cos β = 0) the B term is left out.
// Both are reciprocal and isotropic. Pure.
#pragma once

#include "core/material/lobe.h"
#include "core/material/spectral_value.h"

namespace brdf::material {

class LambertLobe final : public Lobe {
 public:
  explicit LambertLobe(SpectralValue albedo) : albedo_(std::move(albedo)) {}
  std::string_view type() const override { return "lambert"; }
  void AddTo(const DirectionPair& d, std::span<const double> nm,
             std::span<double> out) const override;

 private:
  SpectralValue albedo_;
};

class OrenNayarLobe final : public Lobe {
 public:
  OrenNayarLobe(SpectralValue albedo, double sigma_deg);
  std::string_view type() const override { return "oren_nayar"; }
  void AddTo(const DirectionPair& d, std::span<const double> nm,
             std::span<double> out) const override;

  // The angular factor A + B · max(0, cos(φi − φo)) · sin α · tan β of a pair.
  double AngularFactor(const DirectionPair& d) const;

 private:
  SpectralValue albedo_;
  double a_ = 1, b_ = 0;
};

}  // namespace brdf::material
