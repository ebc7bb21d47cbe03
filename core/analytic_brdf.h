// A known spectral BRDF in closed form: a diffuse, paint-like base plus a glossy lobe, optionally
// anisotropic. It is the "virtual sample" of brdf-sim, the synthetic sample of the offline demo,
// and the ground truth that tests and benchmarks compare interpolated spectra against.
// Pure and deterministic. Values in sr⁻¹.
#pragma once

#include <span>
#include <vector>

#include "core/pose.h"
#include "core/wavelength_grid.h"

namespace brdf {

struct AnalyticBrdfParams {
  // Diffuse albedo as a smooth function of wavelength: albedo(λ) = base +
  // amp·exp(−((λ−peak)/width)²) (a warm paint by default), divided by π for the Lambertian BRDF.
  double diffuse_base = 0.25;
  double diffuse_amp = 0.45;
  double diffuse_peak_nm = 610;
  double diffuse_width_nm = 90;
  // Glossy lobe (Blinn-Phong on the half vector, energy-normalised), spectrally flat, scaled by
  // specular_weight. Exponents along the tangent (x) and bitangent (y) differ when anisotropic.
  double specular_weight = 0.08;
  double exponent_x = 60;
  double exponent_y = 60;
};

class AnalyticBrdf {
 public:
  explicit AnalyticBrdf(AnalyticBrdfParams params = {}) : p_(params) {}

  // The default paint-like isotropic sample, and an anisotropic (brushed) variant.
  static AnalyticBrdf PaintLike();
  static AnalyticBrdf Brushed();
  // A glossy isotropic variant: the paint's diffuse base under a stronger, narrower lobe
  // (specular_weight 0.3, exponent 200: the lobe falls to half at θh ≈ 4.7°), the sample on which
  // interpolation near the specular peak is judged.
  static AnalyticBrdf Glossy();

  bool anisotropic() const { return p_.exponent_x != p_.exponent_y; }
  const AnalyticBrdfParams& params() const { return p_; }

  // f(λ) in sr⁻¹ for directions in the sample frame (degrees). Zero when either direction is
  // below the surface (θ > 90°).
  // (Also zero for θ < 0 and for non-finite angles or wavelength, so that it is finite everywhere.
  // The span overload writes min(out.size(), grid.count) values.)
  double Evaluate(const Directions& d, double wavelength_nm) const;
  void EvaluateSpectrum(const Directions& d, const WavelengthGrid& grid,
                        std::span<double> out) const;
  std::vector<double> EvaluateSpectrum(const Directions& d, const WavelengthGrid& grid) const;

 private:
  AnalyticBrdfParams p_;
};

}  // namespace brdf
