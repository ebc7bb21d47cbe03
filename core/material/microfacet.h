// Microfacet statistics of a rough surface: how the facets' normals are distributed (D), and how
// much of the surface a direction sees lit and unblocked (Smith's Λ), for two slope
// distributions, each with roughness αx along the tangent and αy along the bitangent (αx = αy:
// isotropic):
//   GGX (Walter, Marschner, Li & Torrance 2007, "Trowbridge–Reitz"; anisotropic form as in Heitz
//   2014):
//     D(h) = 1 / (π αx αy (hx²/αx² + hy²/αy² + hz²)²)
//     Λ(ω) = (−1 + sqrt(1 + a⁻²)) / 2
//   Beckmann (Beckmann & Spizzichino 1963; Walter et al. 2007):
//     D(h) = exp(−(hx²/αx² + hy²/αy²) / hz²) / (π αx αy hz⁴)
//     Λ(ω) = (erf(a) − 1) / 2 + exp(−a²) / (2 a √π)
//   with a = ωz / sqrt(αx² ωx² + αy² ωy²) (1 / (α tan θ) when isotropic).
// D is normalised so that ∫ D(h) hz dωh = 1 over the hemisphere. Pure.
#pragma once

#include "core/material/local_frame.h"

namespace brdf::material {

enum class FacetSlopes { kGgx, kBeckmann };

struct Roughness {
  double x = 0.1;  // αx, along the tangent
  double y = 0.1;  // αy, along the bitangent
  bool anisotropic() const { return x != y; }
};

// D(h) in sr⁻¹ for a unit facet normal h (0 where hz ≤ 0).
double FacetDensity(FacetSlopes slopes, const Roughness& alpha, const Vec3& h);

// Smith's Λ(ω) for a unit direction ω above the surface (0 at the normal; grows without bound
// towards grazing).
double SmithLambda(FacetSlopes slopes, const Roughness& alpha, const Vec3& w);

// The height-correlated Smith masking–shadowing term of a pair (Heitz 2014):
// G2 = 1 / (1 + Λ(ωi) + Λ(ωo)), symmetric in the two directions.
double SmithShadowing(FacetSlopes slopes, const Roughness& alpha, const DirectionPair& d);

}  // namespace brdf::material
