#include "core/interp/barycentric.h"

#include <cmath>

#include "core/interp/search/point_cloud.h"

#if defined(__x86_64__) && (defined(__GNUC__) || defined(__clang__))
#include <immintrin.h>
#endif

namespace brdf::interp {
namespace {

using Column = std::array<double, 4>;

// det of the 3×3 matrix whose columns are c0, c1, c2 (rows r0, r1, r2 of each column), expanded
// along the first row. With this order a matrix with two equal columns gives exactly 0 and
// replacing a column by itself gives exactly the same value: that is what makes the weights at a
// vertex exactly one-hot.
double Det3(const Column& c0, const Column& c1, const Column& c2, int r0, int r1, int r2) {
  const double a = c0[r0], b = c1[r0], c = c2[r0];
  const double d = c0[r1], e = c1[r1], f = c2[r1];
  const double g = c0[r2], h = c1[r2], i = c2[r2];
  return a * (e * i - f * h) - b * (d * i - f * g) + c * (d * h - e * g);
}

// det of the dims×dims matrix with columns cols[0..dims−1]; dims is 3 or 4 (Laplace expansion
// along the first row for 4).
double Det(const std::array<const Column*, 4>& cols, int dims) {
  if (dims == 3) return Det3(*cols[0], *cols[1], *cols[2], 0, 1, 2);
  return (*cols[0])[0] * Det3(*cols[1], *cols[2], *cols[3], 1, 2, 3) -
         (*cols[1])[0] * Det3(*cols[0], *cols[2], *cols[3], 1, 2, 3) +
         (*cols[2])[0] * Det3(*cols[0], *cols[1], *cols[3], 1, 2, 3) -
         (*cols[3])[0] * Det3(*cols[0], *cols[1], *cols[2], 1, 2, 3);
}

}  // namespace

BarycentricWeights Barycentric(std::span<const double* const> vertices, const double* p, int dims) {
  BarycentricWeights out;
  std::array<Column, 4> edges{};
  std::array<double, 4> len2{};
  Column r{};
  for (int k = 0; k < dims; ++k) {
    double sum = 0.0;
    for (int j = 0; j < dims; ++j) {
      edges[k][j] = vertices[k + 1][j] - vertices[0][j];
      sum += edges[k][j] * edges[k][j];
    }
    len2[k] = sum;
  }
  for (int j = 0; j < dims; ++j) r[j] = p[j] - vertices[0][j];

  std::array<const Column*, 4> cols{&edges[0], &edges[1], &edges[2], &edges[3]};
  const double det = Det(cols, dims);
  // The degenerate test compares |det| with Hadamard's bound H = Π|e_k| (a product of square
  // roots). H is within a few rounding errors of sqrt(P), P = Π|e_k|², so when det² clears
  // (1e-12)²·P with a margin the answer is known without a root; only near the threshold, or
  // where the squares could overflow or underflow, is H computed exactly as specified.
  double product = 1.0;
  for (int k = 0; k < dims; ++k) product *= len2[k];
  const double abs_det = std::fabs(det);
  const bool quick_range =
      product > 1e-280 && product < 1e280 && abs_det > 1e-140 && abs_det < 1e140;
  if (!(quick_range && det * det > kDegenerateRelativeVolume * kDegenerateRelativeVolume * product *
                                       (1.0 + 1e-9))) {
    double hadamard = 1.0;
    for (int k = 0; k < dims; ++k) hadamard *= std::sqrt(len2[k]);
    if (!(abs_det > kDegenerateRelativeVolume * hadamard)) return out;  // also NaN
  }

  // Cramer's rule. A weight below the tolerance decides "outside" at once: the later ones
  // cannot change that. A numerator of the other sign than det and larger than 2·tolerance·|det|
  // makes that weight < −tolerance whatever the rounding, without the division.
  out.fit = SimplexFit::kOutside;
  std::array<double, kMaxSimplexVertices> lambda{};
  double sum_mu = 0.0;
  for (int k = 0; k < dims; ++k) {
    cols[k] = &r;
    const double numerator = Det(cols, dims);
    cols[k] = &edges[k];
    if ((numerator < 0.0) != (det < 0.0) && numerator != 0.0 &&
        std::fabs(numerator) > 2.0 * kEnclosingTolerance * abs_det) {
      return out;
    }
    lambda[k + 1] = numerator / det;
    if (!(lambda[k + 1] >= -kEnclosingTolerance)) return out;
    sum_mu += lambda[k + 1];
  }
  lambda[0] = 1.0 - sum_mu;
  if (!(lambda[0] >= -kEnclosingTolerance)) return out;

  double total = 0.0;
  for (int k = 0; k <= dims; ++k) {
    lambda[k] = lambda[k] > 0.0 ? lambda[k] : 0.0;
    total += lambda[k];
  }
  for (int k = 0; k <= dims; ++k) out.weights[k] = lambda[k] / total;
  out.fit = SimplexFit::kEncloses;
  return out;
}

namespace {

// The blend of 4 or 5 vertex spectra, one band at a time: ((w0·s0 + w1·s1) + w2·s2) + …, the same
// expression in every variant (the vector ones compute it for 4 or 8 bands at once, rounding each
// product before it is added, exactly like the scalar code), so all give the same bits.
template <int V>
void BlendScalar(const double* w, const double* const* s, double* out, std::size_t first,
                 std::size_t bands) {
  for (std::size_t b = first; b < bands; ++b) {
    double sum = RoundedProduct(w[0], s[0][b]);
    for (int k = 1; k < V; ++k) sum = sum + RoundedProduct(w[k], s[k][b]);
    out[b] = sum;
  }
}

#if defined(__x86_64__) && (defined(__GNUC__) || defined(__clang__))
template <int V>
__attribute__((target("avx2"))) void BlendAvx2(const double* w, const double* const* s, double* out,
                                               std::size_t bands) {
  __m256d wv[V];
  for (int k = 0; k < V; ++k) wv[k] = _mm256_set1_pd(w[k]);
  std::size_t b = 0;
  for (; b + 4 <= bands; b += 4) {
    __m256d sum = _mm256_mul_pd(wv[0], _mm256_loadu_pd(s[0] + b));
    asm("" : "+x"(sum));
    for (int k = 1; k < V; ++k) {
      __m256d term = _mm256_mul_pd(wv[k], _mm256_loadu_pd(s[k] + b));
      asm("" : "+x"(term));  // round the product: no fused multiply-add
      sum = _mm256_add_pd(sum, term);
    }
    _mm256_storeu_pd(out + b, sum);
  }
  if (b == bands) return;
  // The last 1–3 bands (101 = 25 · 4 + 1) with masked loads and stores, the same operations per
  // lane: a scalar loop here waited on the last cache line of every spectrum in turn.
  const __m256i lanes = _mm256_set_epi64x(3, 2, 1, 0);
  const __m256i mask =
      _mm256_cmpgt_epi64(_mm256_set1_epi64x(static_cast<long long>(bands - b)), lanes);
  __m256d sum = _mm256_mul_pd(wv[0], _mm256_maskload_pd(s[0] + b, mask));
  asm("" : "+x"(sum));
  for (int k = 1; k < V; ++k) {
    __m256d term = _mm256_mul_pd(wv[k], _mm256_maskload_pd(s[k] + b, mask));
    asm("" : "+x"(term));
    sum = _mm256_add_pd(sum, term);
  }
  _mm256_maskstore_pd(out + b, mask, sum);
}

template <int V>
__attribute__((target("avx512f"))) void BlendAvx512(const double* w, const double* const* s,
                                                    double* out, std::size_t bands) {
  __m512d wv[V];
  for (int k = 0; k < V; ++k) wv[k] = _mm512_set1_pd(w[k]);
  std::size_t b = 0;
  for (; b + 8 <= bands; b += 8) {
    __m512d sum = _mm512_mul_pd(wv[0], _mm512_loadu_pd(s[0] + b));
    asm("" : "+v"(sum));
    for (int k = 1; k < V; ++k) {
      __m512d term = _mm512_mul_pd(wv[k], _mm512_loadu_pd(s[k] + b));
      asm("" : "+v"(term));  // round the product: no fused multiply-add
      sum = _mm512_add_pd(sum, term);
    }
    _mm512_storeu_pd(out + b, sum);
  }
  if (b == bands) return;
  // The last 1–7 bands with masked loads and stores (see BlendAvx2).
  const auto mask = static_cast<__mmask8>((1u << (bands - b)) - 1u);
  __m512d sum = _mm512_mul_pd(wv[0], _mm512_maskz_loadu_pd(mask, s[0] + b));
  asm("" : "+v"(sum));
  for (int k = 1; k < V; ++k) {
    __m512d term = _mm512_mul_pd(wv[k], _mm512_maskz_loadu_pd(mask, s[k] + b));
    asm("" : "+v"(term));
    sum = _mm512_add_pd(sum, term);
  }
  _mm512_mask_storeu_pd(out + b, mask, sum);
}
#endif

using BlendFn = void (*)(const double*, const double* const*, double*, std::size_t);

template <int V>
BlendFn PickBlend() {
#if defined(__x86_64__) && (defined(__GNUC__) || defined(__clang__))
  if (__builtin_cpu_supports("avx512f")) return &BlendAvx512<V>;
  if (__builtin_cpu_supports("avx2")) return &BlendAvx2<V>;
#endif
  return [](const double* w, const double* const* s, double* out, std::size_t bands) {
    BlendScalar<V>(w, s, out, 0, bands);
  };
}

}  // namespace

void BlendSpectra(std::span<const double> weights, std::span<const double* const> spectra,
                  std::span<double> out) {
  // One pass over all vertex spectra (their memory streams in parallel). Each band is summed as
  // ((w0·s0 + w1·s1) + w2·s2) + …, the same order for every vertex count.
  static const BlendFn blend4 = PickBlend<4>();
  static const BlendFn blend5 = PickBlend<5>();
  const std::size_t bands = out.size();
  switch (weights.size()) {
    case 4:
      return blend4(weights.data(), spectra.data(), out.data(), bands);
    case 5:
      return blend5(weights.data(), spectra.data(), out.data(), bands);
    default: {
      const double* s0 = spectra[0];
      const double w0 = weights[0];
      for (std::size_t b = 0; b < bands; ++b) out[b] = RoundedProduct(w0, s0[b]);
      for (std::size_t k = 1; k < weights.size(); ++k) {
        const double w = weights[k];
        const double* s = spectra[k];
        for (std::size_t b = 0; b < bands; ++b) out[b] = out[b] + RoundedProduct(w, s[b]);
      }
    }
  }
}

}  // namespace brdf::interp
