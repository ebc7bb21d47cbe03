// The geometry of the paper's octant method that does not depend on how the nearest points are
// found: how orthants are numbered and named, how the cube of winners is cut into simplices, and
// how the answer is assembled from the winners. Both octant implementations (the brute-force
// reference and the indexed one) end here, so they agree bit for bit whenever their searches
// agree. See docs/interpolation.md. Pure: no I/O.
#pragma once

#include <array>
#include <cstdint>
#include <limits>
#include <span>
#include <string>

#include "core/interp/interpolator.h"
#include "core/interp/search/point_cloud.h"

namespace brdf::interp {

inline constexpr int kMaxDims = 4;
inline constexpr int kMaxOrthants = 1 << kMaxDims;
// "No point in this orthant" in a winners array.
inline constexpr std::uint32_t kNoPoint = std::numeric_limits<std::uint32_t>::max();

// Orthants are numbered by bit pattern: bit j is set when coordinate j is on the "+" side, i.e.
// x[j] >= p[j] (a point on a splitting plane belongs to the + side). In 3D (axes θi, θo, φ) the
// paper's letters are A=0 (−,−,−), B=1 (+,−,−), C=3 (+,+,−), D=2 (−,+,−), E=4 (−,−,+), F=5 (+,−,+),
// G=7 (+,+,+), H=6 (−,+,+). A point with a NaN coordinate (or a NaN query) is in no orthant.
template <int D>
inline int OrthantOf(const double* x, const double* p) {
  int code = 0;
#pragma GCC unroll 4
  for (int j = 0; j < D; ++j) code |= (x[j] >= p[j] ? 1 : 0) << j;
  return code;
}
inline int OrthantOf(const double* x, const double* p, int dims) {
  return dims == 3 ? OrthantOf<3>(x, p) : OrthantOf<4>(x, p);
}

// "A" … "H" for 3D orthants (the paper's corner letters).
char OctantLetter(int orthant);
// "octant E (θi−, θo−, φ+)" in 3D, "orthant 5 (θi+, φi−, θo+, φo−)" in 4D; made once (an empty
// octant's answer names them, and a grid export asks for thousands).
const std::string& OrthantName(int orthant, int dims);

// The simplices of the cube of winners, in the order they are tried, as orthant numbers
// (dims + 1 per simplex; the vertices of an answer come in this order).
//   3D: the paper's five tetrahedra ABCF, ACDH, AEFH, CFGH, ACFH.
//   4D: the Kuhn (Freudenthal) triangulation: one simplex per permutation π of the axes
//       (0, 1, 2, 3), permutations in lexicographic order; the simplex walks from corner 0 (all −)
//       to corner 15 (all +) setting bit π0, then π1, π2, π3. All 24 share the main diagonal 0–15.
struct CubeSimplex {
  int corners[kMaxDims + 1];
};
std::span<const CubeSimplex> CubeSimplices(int dims);
// "tetrahedron ACFH" in 3D; "Kuhn simplex 3 of 24 (corners 0-1-5-7-15)" in 4D (built once).
const std::string& SimplexName(int simplex_index, int dims);

// The result of the octant method's search: per orthant o, the rank (in the PointCloud) of the
// point nearest to the query, or kNoPoint, and a pointer to that point's scaled coordinates
// (wherever the search keeps a copy; the values are the cloud's). A search may keep the copies in
// `coords` (the k-d tree does: its own copy is per axis, and the cloud's may be cold in cache);
// `scaled` then points into this very object, so read the winners where the search left them.
struct OrthantWinners {
  std::array<std::uint32_t, kMaxOrthants> rank;
  std::array<const double*, kMaxOrthants> scaled;
  std::array<std::array<double, kMaxDims>, kMaxOrthants> coords;
};

// Asks the memory system for every cache line of a spectrum, so that the lines of several
// spectra arrive in parallel instead of one stream after another.
inline void PrefetchSpectrum(std::span<const double> spectrum) {
  const char* p = reinterpret_cast<const char*>(spectrum.data());
  const char* end = reinterpret_cast<const char*>(spectrum.data() + spectrum.size());
  for (; p < end; p += 64) __builtin_prefetch(p);
}

// Steps 3 and 4 of the method without the spectrum and without allocating: which simplex of the
// cube of winners encloses the query, its vertices and their weights.
struct OctantBlend {
  InterpStatus status = InterpStatus::kEmptyOctant;
  // kEmptyOctant: bit o set for every orthant o that holds no sample.
  std::uint32_t empty_orthants = 0;
  // kOk: the index in CubeSimplices(dims) of the first simplex that encloses the query.
  int simplex = -1;
  // Flat simplices skipped on the way (all of them when none encloses the query).
  int degenerate = 0;
  // kOk: the vertices' ranks in the cloud and their barycentric weights, in the simplex's order.
  std::array<std::uint32_t, kMaxDims + 1> rank{};
  std::array<double, kMaxDims + 1> weight{};
};

// `scaled_query` is the query in the cloud's scaled space. Empty orthant → kEmptyOctant;
// otherwise the first simplex of CubeSimplices that encloses the query (degenerate ones are
// skipped) → kOk; none → kNoEnclosingSimplex.
OctantBlend FindOctantBlend(const OrthantWinners& winners, std::span<const double> scaled_query,
                            int dims);

// FindOctantBlend, the same result bit for bit, faster where the CPU allows: in 3D the five
// tetrahedra are tested at once, one per vector lane (AVX-512: one register; AVX2: the first four
// in one, the central ACFH in a second, both always computed), with Barycentric's operations in
// Barycentric's order (no fused multiply-add), and the first that encloses the query is taken.
// On random rig poses the AVX2 path takes about 0.4× the scalar time. What the indexed octant
// method uses; the reference keeps FindOctantBlend.
// `kernel` is for tests and benchmarks: kBest picks the widest the CPU supports; a kernel it
// lacks falls back to kScalar (FindOctantBlend). All give the same blend.
enum class BlendKernel { kBest, kScalar, kAvx2, kAvx512 };
bool BlendKernelSupported(BlendKernel kernel);
OctantBlend FindOctantBlendFast(const OrthantWinners& winners, std::span<const double> scaled_query,
                                int dims, BlendKernel kernel = BlendKernel::kBest);

// A 3D cube of winners laid out as the vector kernels read it (what batches fill straight from
// the search, KdTree::NearestPerOrthantInCell): lane o of axis[j] is coordinate j (scaled) of the
// winner in orthant o, rank[o] its rank in the cloud; `empty` has bit o set when orthant o holds
// no point (its lanes are not read).
struct WinnerCube3 {
  alignas(64) std::array<std::array<double, 8>, 3> axis;
  std::array<std::uint32_t, 8> rank;
  std::uint32_t empty = 0;
};
// FindOctantBlendFast for a cube in that layout: the same blend, bit for bit.
OctantBlend FindOctantBlendFast(const WinnerCube3& cube, const double* scaled_query,
                                BlendKernel kernel = BlendKernel::kBest);

// The blended spectrum of a kOk blend: out[b] = Σ_k weight_k · spectrum_k[b] in vertex order
// (BlendSpectra). out.size() == samples.bands().
void BlendOctantSpectrum(const PointCloud& cloud, const SampleSet& samples,
                         const OctantBlend& blend, std::span<double> out);

// The complete answer of a blend: status, vertices (ids, indices, coordinates, weights), blended
// spectrum and detail (which simplex enclosed the query; which orthants were empty, by name).
Interpolation OctantInterpolation(const PointCloud& cloud, const SampleSet& samples,
                                  const OctantBlend& blend);

// Builds the octant method's answer from the winners:
// OctantInterpolation(cloud, samples, FindOctantBlend(winners, scaled_query, cloud.dims)).
Interpolation AssembleOctantAnswer(const PointCloud& cloud, const SampleSet& samples,
                                   const OrthantWinners& winners,
                                   std::span<const double> scaled_query);

// The answer for a query that has the wrong number of coordinates or a non-finite one, with the
// failure status the method uses for "no data around here" (octant: kEmptyOctant, since no orthant
// of a NaN query holds a sample; nearest: kOutsideHull). The detail says what is wrong.
Interpolation InvalidQueryAnswer(Method method, InterpStatus status, std::span<const double> query,
                                 int dims);
// True when the query has `dims` finite coordinates.
bool ValidQuery(std::span<const double> query, int dims);

}  // namespace brdf::interp
