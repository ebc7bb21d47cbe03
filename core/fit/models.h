// The analytic reflection models the fits evaluate, at one wavelength, for isotropic directions
// (θi, θo, φ) in degrees, values in sr⁻¹. The directions are placed in the sample frame as
// ωi = (sin θi, 0, cos θi) and ωo = (sin θo cos φ, sin θo sin φ, cos θo), so that φ = 180° is the
// specular side (geometry.md).
//
//   Lambert        f = ρ / π                       (ρ: the albedo, in [0, 1] for a real surface)
//   Cook-Torrance  f = kd / π + ks · D(h) · F(ωi·h) · G1(ωi) · G1(ωo) / (4 cos θi cos θo)
//     with the GGX (Trowbridge-Reitz) distribution D(h) = α² / (π ((n·h)² (α² − 1) + 1)²),
//     Smith's separable masking G1(ω) = 2 cos θ / (cos θ + √(α² + (1 − α²) cos² θ)) and
//     Schlick's Fresnel F(c) = F0 + (1 − F0)(1 − c)⁵.
// α is the GGX roughness (the slope scale; α² is Walter et al.'s), F0 the reflectance at normal
// incidence. ks scales the whole lobe: a plain dielectric has ks ≈ 1 and F0 ≈ 0.04; a coloured
// specular (a metal) shows up as ks varying with wavelength. G1/cos θ is computed in a form that
// stays finite at grazing directions.
#pragma once

#include <span>

#include "core/pose.h"

namespace brdf::fit {

double LambertBrdf(double albedo);

struct CookTorranceParams {
  double kd = 0;     // diffuse albedo: the diffuse term is kd / π
  double ks = 0;     // specular scale
  double alpha = 0;  // GGX roughness, > 0
  double f0 = 0;     // Schlick's normal-incidence reflectance, in [0, 1]
};

// The angles the lobe depends on, computed once per direction so that a fit can evaluate many
// (α, F0) cheaply. `above` is false when either direction is below the surface.
struct LobeGeometry {
  double cos_i = 0, cos_o = 0;  // n·ωi, n·ωo
  double cos_h = 0;             // n·h
  double cos_d = 0;             // ωi·h
  bool above = false;
};
LobeGeometry LobeGeometryOf(const IsoDirection& at);
double CookTorranceSpecularAt(const LobeGeometry& g, double alpha, double f0);

// The specular lobe for ks = 1: D · F · G1(ωi) · G1(ωo) / (4 cos θi cos θo). 0 when either
// direction is below the surface.
double CookTorranceSpecular(const IsoDirection& at, double alpha, double f0);

double CookTorranceBrdf(const IsoDirection& at, const CookTorranceParams& p);

// A fitted model's spectrum at one direction: out[b] = CookTorranceBrdf(at, band[b]) bit for bit
// for b < min(band.size(), out.size()) (later entries of out untouched), with the direction's
// geometry g = LobeGeometryOf(at) computed once by the caller and the lobe's value once per run
// of bands with the same α and F0 (every band's, when the fit shares them).
void CookTorranceSpectrumAt(const LobeGeometry& g, std::span<const CookTorranceParams> band,
                            std::span<double> out);

}  // namespace brdf::fit
