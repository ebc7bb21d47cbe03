#include "core/interp/octant/cube.h"

#include <algorithm>
#include <array>
#include <bit>
#include <cmath>
#include <vector>

#include "core/interp/barycentric.h"

#if defined(__x86_64__) && (defined(__GNUC__) || defined(__clang__))
#define BRDF_CUBE_X86 1
#include <immintrin.h>
#endif

namespace brdf::interp {
namespace {

constexpr std::array<int, 8> kOrthantOfLetter = {0, 1, 3, 2, 4, 5, 7, 6};  // A … H

// The paper's five tetrahedra, in the paper's order: corners B, D, E, G cut off, then the centre.
constexpr std::array<CubeSimplex, 5> kTetrahedra = {{
    {{0, 1, 3, 5, 0}},  // ABCF
    {{0, 3, 2, 6, 0}},  // ACDH
    {{0, 4, 5, 6, 0}},  // AEFH
    {{3, 5, 7, 6, 0}},  // CFGH
    {{0, 3, 5, 6, 0}},  // ACFH
}};
// FindOctantBlend3Avx2 (below) has these corners built in.
static_assert(kTetrahedra[0].corners[0] == 0 && kTetrahedra[1].corners[0] == 0 &&
              kTetrahedra[2].corners[0] == 0 && kTetrahedra[3].corners[0] == 3 &&
              kTetrahedra[0].corners[1] == 1 && kTetrahedra[1].corners[1] == 3 &&
              kTetrahedra[2].corners[1] == 4 && kTetrahedra[3].corners[1] == 5 &&
              kTetrahedra[0].corners[2] == 3 && kTetrahedra[1].corners[2] == 2 &&
              kTetrahedra[2].corners[2] == 5 && kTetrahedra[3].corners[2] == 7 &&
              kTetrahedra[0].corners[3] == 5 && kTetrahedra[1].corners[3] == 6 &&
              kTetrahedra[2].corners[3] == 6 && kTetrahedra[3].corners[3] == 6 &&
              kTetrahedra[4].corners[0] == 0 && kTetrahedra[4].corners[1] == 3 &&
              kTetrahedra[4].corners[2] == 5 && kTetrahedra[4].corners[3] == 6);

std::array<CubeSimplex, 24> MakeKuhnSimplices() {
  std::array<CubeSimplex, 24> out{};
  std::array<int, 4> perm = {0, 1, 2, 3};
  int s = 0;
  do {
    int corner = 0;
    out[s].corners[0] = corner;
    for (int k = 0; k < 4; ++k) {
      corner |= 1 << perm[k];
      out[s].corners[k + 1] = corner;
    }
    ++s;
  } while (std::next_permutation(perm.begin(), perm.end()));
  return out;
}

const char* AxisName(int axis, int dims) {
  static const char* const k3[] = {"θi", "θo", "φ"};
  static const char* const k4[] = {"θi", "φi", "θo", "φo"};
  return dims == 3 ? k3[axis] : k4[axis];
}

std::string Signs(int orthant, int dims) {
  std::string out = "(";
  for (int j = 0; j < dims; ++j) {
    if (j > 0) out += ", ";
    out += AxisName(j, dims);
    out += (orthant >> j) & 1 ? "+" : "−";
  }
  return out + ")";
}

}  // namespace

char OctantLetter(int orthant) {
  for (int k = 0; k < 8; ++k) {
    if (kOrthantOfLetter[k] == orthant) return static_cast<char>('A' + k);
  }
  return '?';
}

const std::string& OrthantName(int orthant, int dims) {
  static const auto kNames = [] {
    std::array<std::array<std::string, 16>, 2> names;  // [0]: 3D (8 used), [1]: 4D
    for (int o = 0; o < 8; ++o) {
      names[0][o] = std::string("octant ") + OctantLetter(o) + " " + Signs(o, 3);
    }
    for (int o = 0; o < 16; ++o) names[1][o] = "orthant " + std::to_string(o) + " " + Signs(o, 4);
    return names;
  }();
  return kNames[dims == 3 ? 0 : 1][static_cast<std::size_t>(orthant)];
}

std::span<const CubeSimplex> CubeSimplices(int dims) {
  static const std::array<CubeSimplex, 24> kKuhn = MakeKuhnSimplices();
  if (dims == 3) return kTetrahedra;
  return kKuhn;
}

const std::string& SimplexName(int simplex_index, int dims) {
  static const auto kNames = [] {
    std::array<std::vector<std::string>, 2> names;  // [0]: 3D, [1]: 4D
    for (int d = 3; d <= 4; ++d) {
      const auto simplices = CubeSimplices(d);
      for (std::size_t s = 0; s < simplices.size(); ++s) {
        std::string name;
        if (d == 3) {
          name = "tetrahedron ";
          for (int k = 0; k < 4; ++k) name += OctantLetter(simplices[s].corners[k]);
        } else {
          name = "Kuhn simplex " + std::to_string(s) + " of 24 (corners ";
          for (int k = 0; k <= d; ++k) {
            if (k > 0) name += "-";
            name += std::to_string(simplices[s].corners[k]);
          }
          name += ")";
        }
        names[static_cast<std::size_t>(d - 3)].push_back(std::move(name));
      }
    }
    return names;
  }();
  return kNames[static_cast<std::size_t>(dims - 3)][static_cast<std::size_t>(simplex_index)];
}

bool ValidQuery(std::span<const double> query, int dims) {
  if (query.size() != static_cast<std::size_t>(dims)) return false;
  // x − x is 0 for a finite x and NaN for ±inf and NaN: one comparison for all coordinates.
  double zero = 0.0;
  for (double x : query) zero += x - x;
  return zero == 0.0;
}

Interpolation InvalidQueryAnswer(Method method, InterpStatus status, std::span<const double> query,
                                 int dims) {
  Interpolation out;
  out.method = method;
  out.status = status;
  if (query.size() != static_cast<std::size_t>(dims)) {
    out.detail = "the query has " + std::to_string(query.size()) +
                 " coordinates; the samples have " + std::to_string(dims);
    return out;
  }
  for (std::size_t j = 0; j < query.size(); ++j) {
    if (!std::isfinite(query[j])) {
      out.detail = std::string("query coordinate ") + AxisName(static_cast<int>(j), dims) +
                   " is not a finite number";
      break;
    }
  }
  return out;
}

OctantBlend FindOctantBlend(const OrthantWinners& winners, std::span<const double> scaled_query,
                            int dims) {
  const int orthants = 1 << dims;
  OctantBlend out;
  for (int o = 0; o < orthants; ++o) {
    if (winners.rank[static_cast<std::size_t>(o)] == kNoPoint) out.empty_orthants |= 1u << o;
  }
  if (out.empty_orthants != 0) return out;

  const auto simplices = CubeSimplices(dims);
  const auto vertex_count = static_cast<std::size_t>(dims + 1);
  std::array<const double*, kMaxSimplexVertices> vertex_points{};
  for (std::size_t s = 0; s < simplices.size(); ++s) {
    for (std::size_t k = 0; k < vertex_count; ++k) {
      vertex_points[k] = winners.scaled[static_cast<std::size_t>(simplices[s].corners[k])];
    }
    const BarycentricWeights bw =
        Barycentric(std::span(vertex_points.data(), vertex_count), scaled_query.data(), dims);
    if (bw.fit == SimplexFit::kDegenerate) ++out.degenerate;
    if (bw.fit != SimplexFit::kEncloses) continue;
    out.status = InterpStatus::kOk;
    out.simplex = static_cast<int>(s);
    for (std::size_t k = 0; k < vertex_count; ++k) {
      out.rank[k] = winners.rank[static_cast<std::size_t>(simplices[s].corners[k])];
      out.weight[k] = bw.weights[k];
    }
    return out;
  }
  out.status = InterpStatus::kNoEnclosingSimplex;
  return out;
}

#ifdef BRDF_CUBE_X86
namespace {

// The blend of a query that tetrahedron t encloses, with the unclamped barycentric coordinates
// lambda (vertex order), as Barycentric finishes it: negative ones clamped to 0, each divided by
// their sum. rank: the winners' ranks by orthant.
inline void SetEnclosed(int t, double (&lambda)[4], const std::uint32_t* rank, OctantBlend& out) {
  double total = 0.0;
#pragma GCC unroll 4
  for (int k = 0; k < 4; ++k) {
    lambda[k] = lambda[k] > 0.0 ? lambda[k] : 0.0;
    total += lambda[k];
  }
  out.status = InterpStatus::kOk;
  out.simplex = t;
  for (std::size_t k = 0; k < 4; ++k) {
    out.rank[k] = rank[kTetrahedra[static_cast<std::size_t>(t)].corners[k]];
    out.weight[k] = lambda[k] / total;
  }
}

// a · b rounded before any addition (no fused multiply-add), 8 lanes.
__attribute__((target("avx512f"))) inline __m512d Mul8(__m512d a, __m512d b) {
  __m512d r = _mm512_mul_pd(a, b);
  asm("" : "+v"(r));
  return r;
}

// Det3 of barycentric.cc lane by lane: columns c0, c1, c2 (rows 0, 1, 2),
// a(ei − fh) − b(di − fg) + c(dh − eg).
__attribute__((target("avx512f"))) inline __m512d Det3x8(const __m512d* c0, const __m512d* c1,
                                                         const __m512d* c2) {
  const __m512d t0 = Mul8(c0[0], _mm512_sub_pd(Mul8(c1[1], c2[2]), Mul8(c2[1], c1[2])));
  const __m512d t1 = Mul8(c1[0], _mm512_sub_pd(Mul8(c0[1], c2[2]), Mul8(c2[1], c0[2])));
  const __m512d t2 = Mul8(c2[0], _mm512_sub_pd(Mul8(c0[1], c1[2]), Mul8(c1[1], c0[2])));
  return _mm512_add_pd(_mm512_sub_pd(t0, t1), t2);
}

// The phases of Blend3Avx512, inlined into it.
#define BRDF_AVX512_PHASE __attribute__((target("avx512f"), always_inline)) inline

// The five tetrahedra's edges e_k = v_{k+1} − v_0 (columns), their squared lengths, and
// r = p − v_0, lane t for tetrahedron t. x[j]: coordinate j of the winners, lane o for orthant o.
BRDF_AVX512_PHASE void TetrahedraEdges512(const __m512d (&x)[3], const double* p,
                                          __m512d (&e)[3][3], __m512d (&len2)[3], __m512d (&r)[3]) {
  // Vertex k of tetrahedron t: orthant kTetrahedra[t].corners[k].
  const __m512i corner[4] = {
      _mm512_set_epi64(0, 0, 0, 0, 3, 0, 0, 0),  // lanes 7..0
      _mm512_set_epi64(1, 1, 1, 3, 5, 4, 3, 1),
      _mm512_set_epi64(3, 3, 3, 5, 7, 5, 2, 3),
      _mm512_set_epi64(5, 5, 5, 6, 6, 6, 6, 5),
  };
  __m512d v[4][3];
  for (int k = 0; k < 4; ++k) {
    for (int j = 0; j < 3; ++j) v[k][j] = _mm512_maskz_permutexvar_pd(0xFF, corner[k], x[j]);
  }
  for (int k = 0; k < 3; ++k) {
    __m512d sum = _mm512_setzero_pd();
    for (int j = 0; j < 3; ++j) {
      e[k][j] = _mm512_sub_pd(v[k + 1][j], v[0][j]);
      sum = _mm512_add_pd(sum, Mul8(e[k][j], e[k][j]));
    }
    len2[k] = sum;
  }
  for (int j = 0; j < 3; ++j) r[j] = _mm512_sub_pd(_mm512_set1_pd(p[j]), v[0][j]);
}

// The degenerate test, as Barycentric does it: the tetrahedra (bits 0–4) too flat to use.
BRDF_AVX512_PHASE unsigned FlatTetrahedra512(__m512d det, const __m512d (&len2)[3]) {
  const __m512d product = Mul8(Mul8(Mul8(_mm512_set1_pd(1.0), len2[0]), len2[1]), len2[2]);
  const __m512d abs_det = _mm512_abs_pd(det);
  const __mmask8 quick_range = _mm512_cmp_pd_mask(product, _mm512_set1_pd(1e-280), _CMP_GT_OQ) &
                               _mm512_cmp_pd_mask(product, _mm512_set1_pd(1e280), _CMP_LT_OQ) &
                               _mm512_cmp_pd_mask(abs_det, _mm512_set1_pd(1e-140), _CMP_GT_OQ) &
                               _mm512_cmp_pd_mask(abs_det, _mm512_set1_pd(1e140), _CMP_LT_OQ);
  constexpr double kSquaredLimit = kDegenerateRelativeVolume * kDegenerateRelativeVolume;
  const __mmask8 quick_ok =
      quick_range & _mm512_cmp_pd_mask(Mul8(det, det),
                                       Mul8(Mul8(_mm512_set1_pd(kSquaredLimit), product),
                                            _mm512_set1_pd(1.0 + 1e-9)),
                                       _CMP_GT_OQ);
  // Hadamard's bound with its square roots only when the quick test left a tetrahedron open
  // (rarely: square roots of 8 lanes are slow on some CPUs).
  __mmask8 exact_ok = 0;
  if ((quick_ok & 0x1Fu) != 0x1Fu) {
    const __m512d hadamard =
        Mul8(Mul8(Mul8(_mm512_set1_pd(1.0), _mm512_maskz_sqrt_pd(0xFF, len2[0])),
                  _mm512_maskz_sqrt_pd(0xFF, len2[1])),
             _mm512_maskz_sqrt_pd(0xFF, len2[2]));
    exact_ok = _mm512_cmp_pd_mask(
        abs_det, Mul8(_mm512_set1_pd(kDegenerateRelativeVolume), hadamard), _CMP_GT_OQ);
  }
  return static_cast<unsigned>(static_cast<__mmask8>(~(quick_ok | exact_ok))) & 0x1Fu;
}

// Cramer's rule: μ_k = det(edges with e_k replaced by r) / det; outside when some weight is
// below −tolerance. The numerators for every lane; the divisions (slow for 8 lanes on some
// CPUs) only for the lanes Barycentric's shortcut leaves open: a numerator of the other sign
// than det, larger than 2·tolerance·|det|, means outside (kept as it is for the rare inputs
// where rounding could make it disagree with the division). Most tetrahedra of a cube are
// decided by it; about one lane per query is divided. Returns the lanes it decides ("cut").
BRDF_AVX512_PHASE unsigned CramerNumerators512(const __m512d (&e)[3][3], const __m512d (&r)[3],
                                               __m512d det, double (&numerator)[3][8]) {
  const __m512d zero = _mm512_setzero_pd();
  const __m512d abs_det = _mm512_abs_pd(det);
  __mmask8 cut = 0;
  for (int k = 0; k < 3; ++k) {
    const __m512d* c0 = k == 0 ? r : e[0];
    const __m512d* c1 = k == 1 ? r : e[1];
    const __m512d* c2 = k == 2 ? r : e[2];
    const __m512d n = Det3x8(c0, c1, c2);
    const __mmask8 opposite = static_cast<__mmask8>(_mm512_cmp_pd_mask(n, zero, _CMP_LT_OQ) ^
                                                    _mm512_cmp_pd_mask(det, zero, _CMP_LT_OQ));
    cut |= opposite & _mm512_cmp_pd_mask(n, zero, _CMP_NEQ_UQ) &
           _mm512_cmp_pd_mask(_mm512_abs_pd(n),
                              Mul8(_mm512_set1_pd(2.0 * kEnclosingTolerance), abs_det), _CMP_GT_OQ);
    _mm512_store_pd(numerator[k], n);
  }
  return cut;
}

#undef BRDF_AVX512_PHASE

// Barycentric (barycentric.cc) for the five tetrahedra of kTetrahedra at once, lane t for
// tetrahedron t (lanes 5–7 repeat tetrahedron 0 and are ignored). Every lane performs exactly
// the scalar function's operations, in its order, each rounded (no fused multiply-add: the
// products are pinned); the scalar function's early exits skip work whose outcome they already
// know, so computing everything and reading the verdict at the end gives the same answer.
// x[j]: coordinate j of the winners, lane o for orthant o; rank: the winners' ranks by orthant.
__attribute__((target("avx512f"), always_inline)) inline OctantBlend Blend3Avx512(
    const __m512d (&x)[3], const std::uint32_t* rank, const double* p) {
  OctantBlend out;
  __m512d e[3][3];
  __m512d len2[3];
  __m512d r[3];
  TetrahedraEdges512(x, p, e, len2, r);
  const __m512d det = Det3x8(e[0], e[1], e[2]);
  const unsigned flat = FlatTetrahedra512(det, len2);
  alignas(64) double numerator[3][8];
  const unsigned cut = CramerNumerators512(e, r, det, numerator);
  alignas(64) double determinant[8];
  _mm512_store_pd(determinant, det);
  // The divisions, in the scalar code's order, for the open tetrahedra (about one per query).
  double lambda[4];
  for (unsigned open = ~(cut | flat) & 0x1Fu; open != 0; open &= open - 1) {
    const int t = std::countr_zero(open);
    double sum_mu = 0.0;
    bool inside = true;
#pragma GCC unroll 3
    for (int k = 0; k < 3; ++k) {
      lambda[k + 1] = numerator[k][t] / determinant[t];
      inside = inside && lambda[k + 1] >= -kEnclosingTolerance;
      sum_mu += lambda[k + 1];
    }
    lambda[0] = 1.0 - sum_mu;
    if (!inside || !(lambda[0] >= -kEnclosingTolerance)) continue;
    // The first tetrahedron that encloses p.
    out.degenerate = std::popcount(flat & ((1u << t) - 1u));
    SetEnclosed(t, lambda, rank, out);
    return out;
  }
  out.degenerate = std::popcount(flat);
  out.status = InterpStatus::kNoEnclosingSimplex;
  return out;
}

__attribute__((target("avx512f"))) OctantBlend FindOctantBlend3Avx512(const OrthantWinners& winners,
                                                                      const double* p) {
  // The winners' coordinates per axis, one lane per orthant.
  alignas(64) double axis[3][8];
  for (int o = 0; o < 8; ++o) {
    const double* x = winners.scaled[static_cast<std::size_t>(o)];
    for (int j = 0; j < 3; ++j) axis[j][o] = x[j];
  }
  __m512d x[3];
  for (int j = 0; j < 3; ++j) x[j] = _mm512_load_pd(axis[j]);
  return Blend3Avx512(x, winners.rank.data(), p);
}

__attribute__((target("avx512f"))) OctantBlend FindOctantBlend3Avx512(const WinnerCube3& cube,
                                                                      const double* p) {
  const __m512d x[3] = {_mm512_load_pd(cube.axis[0].data()), _mm512_load_pd(cube.axis[1].data()),
                        _mm512_load_pd(cube.axis[2].data())};
  return Blend3Avx512(x, cube.rank.data(), p);
}

// a · b rounded before any addition (no fused multiply-add), 4 lanes.
__attribute__((target("avx2"))) inline __m256d Mul4(__m256d a, __m256d b) {
  __m256d r = _mm256_mul_pd(a, b);
  asm("" : "+x"(r));
  return r;
}

// Det3 of barycentric.cc lane by lane (see Det3x8).
__attribute__((target("avx2"))) inline __m256d Det3x4(const __m256d* c0, const __m256d* c1,
                                                      const __m256d* c2) {
  const __m256d t0 = Mul4(c0[0], _mm256_sub_pd(Mul4(c1[1], c2[2]), Mul4(c2[1], c1[2])));
  const __m256d t1 = Mul4(c1[0], _mm256_sub_pd(Mul4(c0[1], c2[2]), Mul4(c2[1], c0[2])));
  const __m256d t2 = Mul4(c2[0], _mm256_sub_pd(Mul4(c0[1], c1[2]), Mul4(c1[1], c0[2])));
  return _mm256_add_pd(_mm256_sub_pd(t0, t1), t2);
}

__attribute__((target("avx2"))) inline unsigned Mask4(__m256d m) {
  return static_cast<unsigned>(_mm256_movemask_pd(m));
}

// Barycentric (barycentric.cc) for four tetrahedra at once, one per lane: lane l has the
// vertices v[k][·] (k = 0 … 3; one register per axis). Every lane performs exactly the scalar
// function's operations, in its order, each rounded. Returns per lane (bit l): `encloses` and
// `flat` (degenerate), and the unclamped λ_0 … λ_3 in `lambda`.
struct FourTetrahedra {
  unsigned encloses = 0;
  unsigned flat = 0;
  alignas(32) double lambda[4][4];  // [k][lane]
};
__attribute__((target("avx2"), always_inline)) inline void Barycentric4(const __m256d (&v)[4][3],
                                                                        const double* p,
                                                                        FourTetrahedra& out) {
  const __m256d zero = _mm256_setzero_pd();
  __m256d e[3][3];
  __m256d len2[3];
  __m256d r[3];
#pragma GCC unroll 4
  for (int k = 0; k < 3; ++k) {
    __m256d sum = zero;
#pragma GCC unroll 4
    for (int j = 0; j < 3; ++j) {
      e[k][j] = _mm256_sub_pd(v[k + 1][j], v[0][j]);
      sum = _mm256_add_pd(sum, Mul4(e[k][j], e[k][j]));
    }
    len2[k] = sum;
  }
#pragma GCC unroll 4
  for (int j = 0; j < 3; ++j) r[j] = _mm256_sub_pd(_mm256_set1_pd(p[j]), v[0][j]);
  const __m256d det = Det3x4(e[0], e[1], e[2]);
  // The degenerate test as Barycentric does it: the quick comparison of squares, and the exact
  // one with Hadamard's bound (three square roots) only for lanes the quick one did not clear.
  const __m256d one = _mm256_set1_pd(1.0);
  const __m256d product = Mul4(Mul4(Mul4(one, len2[0]), len2[1]), len2[2]);
  const __m256d abs_det = _mm256_andnot_pd(_mm256_set1_pd(-0.0), det);
  const __m256d quick_range =
      _mm256_and_pd(_mm256_and_pd(_mm256_cmp_pd(product, _mm256_set1_pd(1e-280), _CMP_GT_OQ),
                                  _mm256_cmp_pd(product, _mm256_set1_pd(1e280), _CMP_LT_OQ)),
                    _mm256_and_pd(_mm256_cmp_pd(abs_det, _mm256_set1_pd(1e-140), _CMP_GT_OQ),
                                  _mm256_cmp_pd(abs_det, _mm256_set1_pd(1e140), _CMP_LT_OQ)));
  constexpr double kSquaredLimit = kDegenerateRelativeVolume * kDegenerateRelativeVolume;
  const unsigned quick_ok = Mask4(_mm256_and_pd(
      quick_range,
      _mm256_cmp_pd(Mul4(det, det),
                    Mul4(Mul4(_mm256_set1_pd(kSquaredLimit), product), _mm256_set1_pd(1.0 + 1e-9)),
                    _CMP_GT_OQ)));
  unsigned solid = quick_ok;
  if (quick_ok != 0xFu) {
    const __m256d hadamard = Mul4(Mul4(Mul4(one, _mm256_sqrt_pd(len2[0])), _mm256_sqrt_pd(len2[1])),
                                  _mm256_sqrt_pd(len2[2]));
    solid |= Mask4(_mm256_cmp_pd(abs_det, Mul4(_mm256_set1_pd(kDegenerateRelativeVolume), hadamard),
                                 _CMP_GT_OQ));
  }
  out.flat = ~solid & 0xFu;
  // Cramer's rule, with Barycentric's shortcut for a numerator of the other sign than det.
  const __m256d tol = _mm256_set1_pd(-kEnclosingTolerance);
  const __m256d det_negative = _mm256_cmp_pd(det, zero, _CMP_LT_OQ);
  const __m256d shortcut_limit = Mul4(_mm256_set1_pd(2.0 * kEnclosingTolerance), abs_det);
  __m256d inside = _mm256_castsi256_pd(_mm256_set1_epi64x(-1));
  __m256d sum_mu = zero;
#pragma GCC unroll 4
  for (int k = 0; k < 3; ++k) {
    const __m256d* c0 = k == 0 ? r : e[0];
    const __m256d* c1 = k == 1 ? r : e[1];
    const __m256d* c2 = k == 2 ? r : e[2];
    const __m256d numerator = Det3x4(c0, c1, c2);
    const __m256d opposite =
        _mm256_xor_pd(_mm256_cmp_pd(numerator, zero, _CMP_LT_OQ), det_negative);
    const __m256d shortcut =
        _mm256_and_pd(_mm256_and_pd(opposite, _mm256_cmp_pd(numerator, zero, _CMP_NEQ_UQ)),
                      _mm256_cmp_pd(_mm256_andnot_pd(_mm256_set1_pd(-0.0), numerator),
                                    shortcut_limit, _CMP_GT_OQ));
    const __m256d lambda = _mm256_div_pd(numerator, det);
    inside =
        _mm256_and_pd(inside, _mm256_andnot_pd(shortcut, _mm256_cmp_pd(lambda, tol, _CMP_GE_OQ)));
    sum_mu = _mm256_add_pd(sum_mu, lambda);
    _mm256_store_pd(out.lambda[k + 1], lambda);
  }
  const __m256d lambda0 = _mm256_sub_pd(one, sum_mu);
  inside = _mm256_and_pd(inside, _mm256_cmp_pd(lambda0, tol, _CMP_GE_OQ));
  _mm256_store_pd(out.lambda[0], lambda0);
  out.encloses = Mask4(inside) & solid;
}

// The cube of winners per axis: lo[j] holds coordinate j of orthants 0–3 (lane o), hi[j] of
// orthants 4–7. Read one coordinate at a time: the search has just stored them one at a time, and
// a wider load of several such stores would wait for them to reach the cache.
__attribute__((target("avx2"))) inline void CubeAxes(const OrthantWinners& winners,
                                                     __m256d (&lo)[3], __m256d (&hi)[3]) {
  const auto& x = winners.scaled;
#pragma GCC unroll 4
  for (int j = 0; j < 3; ++j) {
    lo[j] = _mm256_set_pd(x[3][j], x[2][j], x[1][j], x[0][j]);
    hi[j] = _mm256_set_pd(x[7][j], x[6][j], x[5][j], x[4][j]);
  }
}

// Lane l of the result: orthant c[l]'s value, from lo (orthants 0–3) or hi (4–7). The corners
// are constants, so this compiles to one or two lane permutes and a blend.
template <int C0, int C1, int C2, int C3>
__attribute__((target("avx2"))) inline __m256d Pick(__m256d lo, __m256d hi) {
  constexpr int kLo = (C0 & 3) | (C1 & 3) << 2 | (C2 & 3) << 4 | (C3 & 3) << 6;
  constexpr int kHiMask = (C0 >> 2) | (C1 >> 2) << 1 | (C2 >> 2) << 2 | (C3 >> 2) << 3;
  if constexpr (kHiMask == 0) return _mm256_permute4x64_pd(lo, kLo);
  if constexpr (kHiMask == 0xF) return _mm256_permute4x64_pd(hi, kLo);
  return _mm256_blend_pd(_mm256_permute4x64_pd(lo, kLo), _mm256_permute4x64_pd(hi, kLo), kHiMask);
}

// FindOctantBlend's answer for a 3D cube of winners with no empty orthant, with AVX2: the first
// four tetrahedra at once (lane t for tetrahedron t) and the fifth (the central ACFH, in every
// lane of a second register). Both are always computed, without a branch between them: the
// central tetrahedron is the one that encloses most queries (60 % of random rig poses), so a
// second pass only when the first four fail would be taken most of the time, behind a branch the
// predictor cannot call. Weights as Barycentric computes them, for the winner alone.
// lo[j], hi[j]: coordinate j of the winners of orthants 0–3 and 4–7 (lane o mod 4); rank: the
// winners' ranks by orthant.
__attribute__((target("avx2"), always_inline)) inline OctantBlend Blend3Avx2(
    const __m256d (&lo)[3], const __m256d (&hi)[3], const std::uint32_t* rank, const double* p) {
  // Vertex k of tetrahedron t is orthant kTetrahedra[t].corners[k] (the static_assert after
  // kTetrahedra): ABCF, ACDH, AEFH, CFGH in the lanes of `first`, ACFH in every lane of `centre`.
  __m256d first[4][3];
  __m256d centre[4][3];
#pragma GCC unroll 4
  for (int j = 0; j < 3; ++j) {
    first[0][j] = Pick<0, 0, 0, 3>(lo[j], hi[j]);
    first[1][j] = Pick<1, 3, 4, 5>(lo[j], hi[j]);
    first[2][j] = Pick<3, 2, 5, 7>(lo[j], hi[j]);
    first[3][j] = Pick<5, 6, 6, 6>(lo[j], hi[j]);
    centre[0][j] = Pick<0, 0, 0, 0>(lo[j], hi[j]);
    centre[1][j] = Pick<3, 3, 3, 3>(lo[j], hi[j]);
    centre[2][j] = Pick<5, 5, 5, 5>(lo[j], hi[j]);
    centre[3][j] = Pick<6, 6, 6, 6>(lo[j], hi[j]);
  }
  FourTetrahedra four;
  FourTetrahedra fifth;
  Barycentric4(first, p, four);
  Barycentric4(centre, p, fifth);
  // Bits 0–3: the first four tetrahedra, bit 4: the central one.
  const unsigned encloses = four.encloses | (fifth.encloses & 1u) << 4;
  const unsigned flat = four.flat | (fifth.flat & 1u) << 4;
  OctantBlend out;
  if (encloses == 0) {
    out.degenerate = std::popcount(flat);
    out.status = InterpStatus::kNoEnclosingSimplex;
    return out;
  }
  const int t = std::countr_zero(encloses);
  out.degenerate = std::popcount(flat & ((1u << t) - 1u));
  const FourTetrahedra& winner = t == 4 ? fifth : four;
  const int lane = t == 4 ? 0 : t;
  double lambda[4];
  for (std::size_t k = 0; k < 4; ++k) lambda[k] = winner.lambda[k][lane];
  SetEnclosed(t, lambda, rank, out);
  return out;
}

__attribute__((target("avx2"))) OctantBlend FindOctantBlend3Avx2(const OrthantWinners& winners,
                                                                 const double* p) {
  __m256d lo[3], hi[3];
  CubeAxes(winners, lo, hi);
  return Blend3Avx2(lo, hi, winners.rank.data(), p);
}

__attribute__((target("avx2"))) OctantBlend FindOctantBlend3Avx2(const WinnerCube3& cube,
                                                                 const double* p) {
  __m256d lo[3], hi[3];
  for (std::size_t j = 0; j < 3; ++j) {
    lo[j] = _mm256_load_pd(cube.axis[j].data());
    hi[j] = _mm256_load_pd(cube.axis[j].data() + 4);
  }
  return Blend3Avx2(lo, hi, cube.rank.data(), p);
}

}  // namespace
#endif

bool BlendKernelSupported(BlendKernel kernel) {
  switch (kernel) {
    case BlendKernel::kBest:
    case BlendKernel::kScalar:
      return true;
#ifdef BRDF_CUBE_X86
    case BlendKernel::kAvx2:
      return __builtin_cpu_supports("avx2");
    case BlendKernel::kAvx512:
      return __builtin_cpu_supports("avx512f");
#else
    case BlendKernel::kAvx2:
    case BlendKernel::kAvx512:
      return false;
#endif
  }
  return false;
}

namespace {

// The kernel a BlendKernel asks for on this CPU. kBest is what every query asks for: it needs no
// check beyond the one made once here.
BlendKernel KernelToRun(BlendKernel kernel) {
  static const BlendKernel best = BlendKernelSupported(BlendKernel::kAvx512) ? BlendKernel::kAvx512
                                  : BlendKernelSupported(BlendKernel::kAvx2) ? BlendKernel::kAvx2
                                                                             : BlendKernel::kScalar;
  if (kernel == BlendKernel::kBest) return best;
  return BlendKernelSupported(kernel) ? kernel : BlendKernel::kScalar;
}

}  // namespace

OctantBlend FindOctantBlendFast(const WinnerCube3& cube, const double* scaled_query,
                                BlendKernel kernel) {
  if (cube.empty != 0) {
    OctantBlend out;
    out.empty_orthants = cube.empty;
    return out;
  }
  kernel = KernelToRun(kernel);
#ifdef BRDF_CUBE_X86
  if (kernel == BlendKernel::kAvx512) return FindOctantBlend3Avx512(cube, scaled_query);
  if (kernel == BlendKernel::kAvx2) return FindOctantBlend3Avx2(cube, scaled_query);
#endif
  OrthantWinners winners;
  for (std::size_t o = 0; o < 8; ++o) {
    winners.rank[o] = cube.rank[o];
    for (std::size_t j = 0; j < 3; ++j) winners.coords[o][j] = cube.axis[j][o];
    winners.scaled[o] = winners.coords[o].data();
  }
  return FindOctantBlend(winners, std::span(scaled_query, 3), 3);
}

OctantBlend FindOctantBlendFast(const OrthantWinners& winners, std::span<const double> scaled_query,
                                int dims, BlendKernel kernel) {
  kernel = KernelToRun(kernel);
#ifdef BRDF_CUBE_X86
  if (dims == 3 && kernel != BlendKernel::kScalar) {
    std::uint32_t empty = 0;
    for (int o = 0; o < 8; ++o) {
      if (winners.rank[static_cast<std::size_t>(o)] == kNoPoint) empty |= 1u << o;
    }
    if (empty != 0) {
      OctantBlend out;
      out.empty_orthants = empty;
      return out;
    }
    return kernel == BlendKernel::kAvx512 ? FindOctantBlend3Avx512(winners, scaled_query.data())
                                          : FindOctantBlend3Avx2(winners, scaled_query.data());
  }
#else
  (void)kernel;
#endif
  return FindOctantBlend(winners, scaled_query, dims);
}

void BlendOctantSpectrum(const PointCloud& cloud, const SampleSet& samples,
                         const OctantBlend& blend, std::span<double> out) {
  const auto vertex_count = static_cast<std::size_t>(cloud.dims + 1);
  // The vertex spectra are scattered over the sample set: start fetching all of them at once.
  std::array<const double*, kMaxSimplexVertices> spectra{};
  for (std::size_t k = 0; k < vertex_count; ++k) {
    spectra[k] = samples.spectrum(cloud.sample[blend.rank[k]]).data();
    PrefetchSpectrum(std::span(spectra[k], static_cast<std::size_t>(samples.bands())));
  }
  BlendSpectra(std::span(blend.weight.data(), vertex_count),
               std::span(spectra.data(), vertex_count), out);
}

Interpolation OctantInterpolation(const PointCloud& cloud, const SampleSet& samples,
                                  const OctantBlend& blend) {
  const int dims = cloud.dims;
  Interpolation out;
  out.method = Method::kOctant;
  out.status = blend.status;
  switch (blend.status) {
    case InterpStatus::kOk:
      break;
    case InterpStatus::kEmptyOctant: {
      std::string empty;
      for (int k = 0; k < (1 << dims); ++k) {
        // In 3D list empty octants in letter order (A … H), in 4D by number.
        const int o = dims == 3 ? kOrthantOfLetter[static_cast<std::size_t>(k)] : k;
        if ((blend.empty_orthants >> o & 1u) == 0) continue;
        empty += empty.empty() ? "" : ", ";
        empty += OrthantName(o, dims);
      }
      out.detail = "no sample in " + empty;
      return out;
    }
    default:
      out.detail = std::string("none of the ") +
                   (dims == 3 ? "5 tetrahedra" : "24 Kuhn simplices") +
                   " of the nearest samples encloses the query";
      if (blend.degenerate > 0) {
        out.detail += " (" + std::to_string(blend.degenerate) + " of them flat)";
      }
      return out;
  }

  const auto vertex_count = static_cast<std::size_t>(dims + 1);
  out.spectrum.resize(static_cast<std::size_t>(samples.bands()));
  BlendOctantSpectrum(cloud, samples, blend, out.spectrum);
  out.vertices.resize(vertex_count);
  for (std::size_t k = 0; k < vertex_count; ++k) {
    const std::uint32_t rank = blend.rank[k];
    const std::uint32_t index = cloud.sample[rank];
    Vertex& v = out.vertices[k];
    v.id = samples.id(index);
    v.index = index;
    const auto p = cloud.point(rank);
    v.coords.assign(p.begin(), p.end());
    v.weight = blend.weight[k];
  }
  out.detail = SimplexName(blend.simplex, dims);
  return out;
}

Interpolation AssembleOctantAnswer(const PointCloud& cloud, const SampleSet& samples,
                                   const OrthantWinners& winners,
                                   std::span<const double> scaled_query) {
  return OctantInterpolation(cloud, samples, FindOctantBlend(winners, scaled_query, cloud.dims));
}

}  // namespace brdf::interp
