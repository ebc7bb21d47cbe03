// Barycentric coordinates of a query in a simplex (tetrahedron in 3D, 4-simplex in 4D), the
// enclosing test built on them, and the blend of vertex spectra with them. Shared by every method
// that blends, so that two searches that find the same vertices give bit-identical answers.
// Pure: no I/O.
#pragma once

#include <array>
#include <span>

namespace brdf::interp {

inline constexpr int kMaxSimplexVertices = 5;  // dims + 1 for dims <= 4

// A simplex whose |det(edges)| is at most this fraction of the product of its edge lengths
// (Hadamard's bound, i.e. relative volume) is degenerate (flat): it cannot enclose anything.
inline constexpr double kDegenerateRelativeVolume = 1e-12;
// A weight down to -kEnclosingTolerance still counts as inside: the query is on a face, and
// rounding put it a hair outside. Such weights are clamped to 0 (see Barycentric).
inline constexpr double kEnclosingTolerance = 1e-12;

enum class SimplexFit { kEncloses, kOutside, kDegenerate };

struct BarycentricWeights {
  SimplexFit fit = SimplexFit::kDegenerate;
  // Vertex weights (dims + 1 of them) when fit == kEncloses: each >= 0, summing to 1.
  std::array<double, kMaxSimplexVertices> weights{};
};

// `vertices` holds dims + 1 pointers to dims coordinates each; `p` has dims coordinates.
// dims is 3 or 4. The computation, fixed so that results are reproducible:
//   edges e_k = v_{k+1} − v_0, r = p − v_0, D = det[e_0 … e_{dims−1}] (cofactor expansion);
//   degenerate when !(|D| > kDegenerateRelativeVolume · Π|e_k|);
//   μ_k = det(edges with e_k replaced by r) / D (Cramer's rule), λ_0 = 1 − (μ_0 + … ), λ_{k+1} =
//   μ_k; encloses when every λ >= −kEnclosingTolerance, whatever the sign of D
//   (orientation-agnostic); weights = max(λ, 0) / Σ max(λ, 0).
// When p is exactly a vertex of a 3D simplex the weights are exactly one-hot.
BarycentricWeights Barycentric(std::span<const double* const> vertices, const double* p, int dims);

// out[b] = Σ_k weights[k] · spectra[k][b], summed in vertex order k = 0, 1, … for every band b.
void BlendSpectra(std::span<const double> weights, std::span<const double* const> spectra,
                  std::span<double> out);

}  // namespace brdf::interp
