// The fraction of light a smooth interface reflects, F(cos θ, λ), for a microfacet lobe (θ the
// angle between the light and the facet's normal, unpolarised light arriving from air):
//   none       F = 1 (the lobe's weight alone sets its strength);
//   Schlick    F = F0 + (1 − F0)(1 − cos θ)⁵ with a spectral F0 (Schlick 1994);
//   conductor  the exact Fresnel equations for a complex index n + ik with spectral n and k
//              (k = 0 gives a dielectric seen from air). Pure.
#pragma once

#include "core/material/spectral_value.h"

namespace brdf::material {

class Fresnel {
 public:
  enum class Kind { kNone, kSchlick, kConductor };

  // F = 1.
  Fresnel() = default;
  static Fresnel Schlick(SpectralValue f0);
  static Fresnel Conductor(SpectralValue n, SpectralValue k);

  // F at `cos_theta` (clamped to [0, 1]) and `nm`; in [0, 1] for F0 in [0, 1], n > 0, k ≥ 0.
  double Reflectance(double cos_theta, double nm) const;
  Kind kind() const { return kind_; }

 private:
  Kind kind_ = Kind::kNone;
  SpectralValue a_, b_;  // F0; or n and k
};

// The exact unpolarised reflectance of an interface from air into a medium of index n + ik.
double ConductorReflectance(double cos_theta, double n, double k);

}  // namespace brdf::material
