#include "core/material/fresnel.h"

#include <algorithm>
#include <cmath>
#include <complex>

namespace brdf::material {

Fresnel Fresnel::Schlick(SpectralValue f0) {
  Fresnel f;
  f.kind_ = Kind::kSchlick;
  f.a_ = std::move(f0);
  return f;
}

Fresnel Fresnel::Conductor(SpectralValue n, SpectralValue k) {
  Fresnel f;
  f.kind_ = Kind::kConductor;
  f.a_ = std::move(n);
  f.b_ = std::move(k);
  return f;
}

double ConductorReflectance(double cos_theta, double n, double k) {
  // Snell's law with a complex index: cos θt = sqrt(1 − sin²θ / η²), the principal root (its
  // real part ≥ 0: the transmitted wave decays into the medium). Then the amplitude
  // coefficients of the s and p polarisations, and the mean of their squared moduli.
  const double c = std::clamp(cos_theta, 0.0, 1.0);
  const std::complex<double> eta(n, k);
  const std::complex<double> cos_t = std::sqrt(1.0 - (1.0 - c * c) / (eta * eta));
  const std::complex<double> rs = (c - eta * cos_t) / (c + eta * cos_t);
  const std::complex<double> rp = (eta * c - cos_t) / (eta * c + cos_t);
  const double f = 0.5 * (std::norm(rs) + std::norm(rp));
  // 0/0 only where the medium is air itself (η = 1) at grazing incidence: the limit there is 1.
  return std::isfinite(f) ? std::clamp(f, 0.0, 1.0) : 1.0;
}

double Fresnel::Reflectance(double cos_theta, double nm) const {
  switch (kind_) {
    case Kind::kNone:
      return 1.0;
    case Kind::kSchlick: {
      const double f0 = a_.At(nm);
      const double m = 1.0 - std::clamp(cos_theta, 0.0, 1.0);
      const double m2 = m * m;
      return f0 + (1.0 - f0) * m2 * m2 * m;
    }
    case Kind::kConductor:
      return ConductorReflectance(cos_theta, a_.At(nm), b_.At(nm));
  }
  return 1.0;
}

}  // namespace brdf::material
