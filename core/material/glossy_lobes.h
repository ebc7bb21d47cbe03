// Lobes that gather light around one direction: the mirror direction (microfacet, Blinn–Phong)
// or the lamp itself (retro-reflection).
//
//   Microfacet (GGX or Beckmann, microfacet.h; Cook & Torrance 1982, Walter et al. 2007):
//     f = w(λ) · F(ωi·h, λ) · D(h) · G2(ωi, ωo) / (4 cos θi cos θo),  h = (ωi + ωo) / |ωi + ωo|,
//     with F from fresnel.h, and G2 Smith's height-correlated term. 0 at exactly grazing.
//   Blinn–Phong (Blinn 1977), energy-normalised as core/analytic_brdf.h does it:
//     f = w(λ) · (e + 8) / (8π) · hz^e, and for ex ≠ ey (Ashikhmin & Shirley 2000's
//     interpolated exponent) e(h) = (ex hx² + ey hy²) / (hx² + hy²) with the normalisation
//     sqrt((ex + 8)(ey + 8)) / (8π). No Fresnel and no 1/cos factors (finite at grazing).
//   Retro-reflective (a cosine lobe about the lamp, Lafortune et al. 1997 with Cx = Cy = Cz = 1):
//     f = w(λ) · (e + 1) / (2π) · max(0, ωi·ωo)^e,
//     whose integral over solid angle about ωi is w: its directional albedo is at most w.
// All three depend on ωi and ωo symmetrically (reciprocal). Pure.
#pragma once

#include "core/material/fresnel.h"
#include "core/material/lobe.h"
#include "core/material/microfacet.h"
#include "core/material/spectral_value.h"

namespace brdf::material {

class MicrofacetLobe final : public Lobe {
 public:
  MicrofacetLobe(FacetSlopes slopes, Roughness alpha, Fresnel fresnel, SpectralValue weight);
  std::string_view type() const override;
  bool anisotropic() const override { return alpha_.anisotropic(); }
  void AddTo(const DirectionPair& d, std::span<const double> nm,
             std::span<double> out) const override;

 private:
  FacetSlopes slopes_;
  Roughness alpha_;
  Fresnel fresnel_;
  SpectralValue weight_;
};

class BlinnPhongLobe final : public Lobe {
 public:
  BlinnPhongLobe(SpectralValue weight, double exponent_x, double exponent_y);
  std::string_view type() const override { return "blinn_phong"; }
  bool anisotropic() const override { return exponent_x_ != exponent_y_; }
  void AddTo(const DirectionPair& d, std::span<const double> nm,
             std::span<double> out) const override;

 private:
  SpectralValue weight_;
  double exponent_x_, exponent_y_;
};

class RetroLobe final : public Lobe {
 public:
  RetroLobe(SpectralValue weight, double exponent);
  std::string_view type() const override { return "retro"; }
  void AddTo(const DirectionPair& d, std::span<const double> nm,
             std::span<double> out) const override;

 private:
  SpectralValue weight_;
  double exponent_;
};

}  // namespace brdf::material
