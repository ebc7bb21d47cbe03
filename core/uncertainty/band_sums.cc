#include "core/uncertainty/band_sums.h"

#include <cmath>
#include <cstddef>
#include <cstring>

#if defined(__x86_64__) && (defined(__GNUC__) || defined(__clang__))
#include <immintrin.h>
#endif

namespace brdf::uncertainty {
namespace {

// W bands at a time in a vector of W doubles (GCC's and Clang's vector extension: the compiler
// emits the widest instructions the function's target allows), the last bands one by one. The
// sizes are spelled out: GCC drops a vector_size that depends on a template parameter.
template <int W>
struct LanesOf;
template <>
struct LanesOf<2> {
  using type = double __attribute__((vector_size(16)));
};
template <>
struct LanesOf<4> {
  using type = double __attribute__((vector_size(32)));
};
template <>
struct LanesOf<8> {
  using type = double __attribute__((vector_size(64)));
};
template <int W>
using Lanes = typename LanesOf<W>::type;
static_assert(sizeof(Lanes<2>) == 16 && sizeof(Lanes<4>) == 32 && sizeof(Lanes<8>) == 64);

// W floats, widened to Lanes<W> as they are read (a blend's shared rows, blend_budget.h).
template <int W>
struct FloatLanesOf;
template <>
struct FloatLanesOf<2> {
  using type = float __attribute__((vector_size(8)));
};
template <>
struct FloatLanesOf<4> {
  using type = float __attribute__((vector_size(16)));
};
template <>
struct FloatLanesOf<8> {
  using type = float __attribute__((vector_size(32)));
};
template <int W>
using FloatLanes = typename FloatLanesOf<W>::type;

// The loops below keep their vectors in locals (never passed or returned: that would change the
// calling convention between targets), loaded and stored with memcpy (no alignment assumed).
template <int W>
[[gnu::always_inline]] inline void AddScaledLanes(double* __restrict acc,
                                                  const double* __restrict x, double a,
                                                  std::size_t n) {
  Lanes<W> s, v;
  std::size_t k = 0;
  for (; k + W <= n; k += W) {
    std::memcpy(&s, acc + k, sizeof s);
    std::memcpy(&v, x + k, sizeof v);
    s += a * v;
    std::memcpy(acc + k, &s, sizeof s);
  }
  for (; k < n; ++k) acc[k] += a * x[k];
}

template <int W>
[[gnu::always_inline]] inline void AddSquaredLanes(double* __restrict acc,
                                                   const double* __restrict x, double a,
                                                   std::size_t n) {
  Lanes<W> s, v;
  std::size_t k = 0;
  for (; k + W <= n; k += W) {
    std::memcpy(&s, acc + k, sizeof s);
    std::memcpy(&v, x + k, sizeof v);
    s += a * (v * v);
    std::memcpy(acc + k, &s, sizeof s);
  }
  for (; k < n; ++k) acc[k] += a * (x[k] * x[k]);
}

template <int W>
[[gnu::always_inline]] inline void AddSquaredDifferenceLanes(double* __restrict acc,
                                                             const double* __restrict x,
                                                             const double* __restrict y, double a,
                                                             std::size_t n) {
  Lanes<W> s, v, w;
  std::size_t k = 0;
  for (; k + W <= n; k += W) {
    std::memcpy(&s, acc + k, sizeof s);
    std::memcpy(&v, x + k, sizeof v);
    std::memcpy(&w, y + k, sizeof w);
    v -= w;
    s += a * (v * v);
    std::memcpy(acc + k, &s, sizeof s);
  }
  for (; k < n; ++k) {
    const double d = x[k] - y[k];
    acc[k] += a * (d * d);
  }
}

template <int W>
[[gnu::always_inline]] inline void AddSquaredSumLanes(double* __restrict acc,
                                                      const double* const* x, const double* w,
                                                      std::size_t m, std::size_t n) {
  Lanes<W> s, v, t;
  std::size_t k = 0;
  for (; k + W <= n; k += W) {
    std::memcpy(&v, x[0] + k, sizeof v);
    t = w[0] * v;
    for (std::size_t i = 1; i < m; ++i) {
      std::memcpy(&v, x[i] + k, sizeof v);
      t += w[i] * v;
    }
    std::memcpy(&s, acc + k, sizeof s);
    s += t * t;
    std::memcpy(acc + k, &s, sizeof s);
  }
  for (; k < n; ++k) {
    double sum = w[0] * x[0][k];
    for (std::size_t i = 1; i < m; ++i) sum += w[i] * x[i][k];
    acc[k] += sum * sum;
  }
}

// BlendSquaredBands' pass (band_sums.h): each band's expressions exactly as the loops above write
// them, so that the compiler forms them alike (the same fused multiply-adds); each float of a
// shared row widened to double as it is read.
template <int W>
[[gnu::always_inline]] inline void BlendSquaredLanes(double* __restrict measurement,
                                                     double* __restrict shared,
                                                     const double* const* independent,
                                                     const double* scales, std::size_t r,
                                                     const WeightedFloatRows* inputs, std::size_t m,
                                                     std::size_t n) {
  const Lanes<W> zero = {};
  Lanes<W> u, s, v, t;
  FloatLanes<W> f;
  std::size_t k = 0;
  for (; k + W <= n; k += W) {
    u = zero;
    for (std::size_t i = 0; i < r; ++i) {
      std::memcpy(&v, independent[i] + k, sizeof v);
      u += scales[i] * (v * v);
    }
    s = zero;
    for (std::size_t j = 0; j < m; ++j) {
      const WeightedFloatRows& in = inputs[j];
      std::memcpy(&f, in.rows[0] + k, sizeof f);
      v = __builtin_convertvector(f, Lanes<W>);
      t = in.weights[0] * v;
      for (std::size_t i = 1; i < in.count; ++i) {
        std::memcpy(&f, in.rows[i] + k, sizeof f);
        v = __builtin_convertvector(f, Lanes<W>);
        t += in.weights[i] * v;
      }
      s += t * t;
    }
    if (shared != nullptr) std::memcpy(shared + k, &s, sizeof s);
    s += u;
    std::memcpy(measurement + k, &s, sizeof s);
  }
  for (; k < n; ++k) {
    double ind = 0;
    for (std::size_t i = 0; i < r; ++i) ind += scales[i] * (independent[i][k] * independent[i][k]);
    double acc = 0;
    for (std::size_t j = 0; j < m; ++j) {
      const WeightedFloatRows& in = inputs[j];
      double sum = in.weights[0] * static_cast<double>(in.rows[0][k]);
      for (std::size_t i = 1; i < in.count; ++i)
        sum += in.weights[i] * static_cast<double>(in.rows[i][k]);
      acc += sum * sum;
    }
    if (shared != nullptr) shared[k] = acc;
    measurement[k] = acc + ind;
  }
}

template <int W>
[[gnu::always_inline]] inline void SquaredDifferencesLanes(double* __restrict acc,
                                                           const double* const* x,
                                                           const double* __restrict y,
                                                           const double* a, std::size_t m,
                                                           std::size_t n) {
  const Lanes<W> zero = {};
  Lanes<W> s, v, w;
  std::size_t k = 0;
  for (; k + W <= n; k += W) {
    std::memcpy(&w, y + k, sizeof w);
    s = zero;
    for (std::size_t i = 0; i < m; ++i) {
      std::memcpy(&v, x[i] + k, sizeof v);
      v -= w;
      s += a[i] * (v * v);
    }
    std::memcpy(acc + k, &s, sizeof s);
  }
  for (; k < n; ++k) {
    double sum = 0;
    for (std::size_t i = 0; i < m; ++i) {
      const double d = x[i][k] - y[k];
      sum += a[i] * (d * d);
    }
    acc[k] = sum;
  }
}

using ScaledFn = void (*)(double*, const double*, double, std::size_t);
using SumFn = void (*)(double*, const double* const*, const double*, std::size_t, std::size_t);
using DifferenceFn = void (*)(double*, const double*, const double*, double, std::size_t);
using SqrtFn = void (*)(double*, std::size_t);
using BlendFloatFn = void (*)(double*, double*, const double* const*, const double*, std::size_t,
                              const WeightedFloatRows*, std::size_t, std::size_t);
using DifferencesFn = void (*)(double*, const double* const*, const double*, const double*,
                               std::size_t, std::size_t);

struct Kernels {
  ScaledFn add_scaled;
  ScaledFn add_squared;
  DifferenceFn add_squared_difference;
  SumFn add_squared_sum;
  SqrtFn sqrt;
  DifferencesFn squared_differences;
  BlendFloatFn blend_squared_float;
};

// The scalar square root (the vector extension has none; the vector variants use intrinsics).
void SqrtScalar(double* x, std::size_t n) {
  for (std::size_t k = 0; k < n; ++k) x[k] = std::sqrt(x[k]);
}

// The baseline (x86-64's SSE2, or whatever the target has): two bands at a time.
void AddScaled2(double* acc, const double* x, double a, std::size_t n) {
  AddScaledLanes<2>(acc, x, a, n);
}
void AddSquared2(double* acc, const double* x, double a, std::size_t n) {
  AddSquaredLanes<2>(acc, x, a, n);
}
void AddSquaredDifference2(double* acc, const double* x, const double* y, double a, std::size_t n) {
  AddSquaredDifferenceLanes<2>(acc, x, y, a, n);
}
void AddSquaredSum2(double* acc, const double* const* x, const double* w, std::size_t m,
                    std::size_t n) {
  AddSquaredSumLanes<2>(acc, x, w, m, n);
}
void BlendSquaredFloat2(double* m, double* shared, const double* const* ind, const double* scales,
                        std::size_t r, const WeightedFloatRows* inputs, std::size_t count,
                        std::size_t n) {
  BlendSquaredLanes<2>(m, shared, ind, scales, r, inputs, count, n);
}
void SquaredDifferences2(double* acc, const double* const* x, const double* y, const double* a,
                         std::size_t m, std::size_t n) {
  SquaredDifferencesLanes<2>(acc, x, y, a, m, n);
}
#if defined(__x86_64__) && (defined(__GNUC__) || defined(__clang__))
void Sqrt2(double* x, std::size_t n) {
  std::size_t k = 0;
  for (; k + 2 <= n; k += 2) _mm_storeu_pd(x + k, _mm_sqrt_pd(_mm_loadu_pd(x + k)));
  SqrtScalar(x + k, n - k);
}
#else
void Sqrt2(double* x, std::size_t n) {
  SqrtScalar(x, n);
}
#endif

#if defined(__x86_64__) && (defined(__GNUC__) || defined(__clang__))
__attribute__((target("avx2"))) void AddScaled4(double* acc, const double* x, double a,
                                                std::size_t n) {
  AddScaledLanes<4>(acc, x, a, n);
}
__attribute__((target("avx2"))) void AddSquared4(double* acc, const double* x, double a,
                                                 std::size_t n) {
  AddSquaredLanes<4>(acc, x, a, n);
}
__attribute__((target("avx2"))) void AddSquaredDifference4(double* acc, const double* x,
                                                           const double* y, double a,
                                                           std::size_t n) {
  AddSquaredDifferenceLanes<4>(acc, x, y, a, n);
}
__attribute__((target("avx2"))) void AddSquaredSum4(double* acc, const double* const* x,
                                                    const double* w, std::size_t m, std::size_t n) {
  AddSquaredSumLanes<4>(acc, x, w, m, n);
}
__attribute__((target("avx2"))) void BlendSquaredFloat4(double* m, double* shared,
                                                        const double* const* ind,
                                                        const double* scales, std::size_t r,
                                                        const WeightedFloatRows* inputs,
                                                        std::size_t count, std::size_t n) {
  BlendSquaredLanes<4>(m, shared, ind, scales, r, inputs, count, n);
}
__attribute__((target("avx2"))) void SquaredDifferences4(double* acc, const double* const* x,
                                                         const double* y, const double* a,
                                                         std::size_t m, std::size_t n) {
  SquaredDifferencesLanes<4>(acc, x, y, a, m, n);
}
__attribute__((target("avx2"))) void Sqrt4(double* x, std::size_t n) {
  std::size_t k = 0;
  for (; k + 4 <= n; k += 4) _mm256_storeu_pd(x + k, _mm256_sqrt_pd(_mm256_loadu_pd(x + k)));
  SqrtScalar(x + k, n - k);
}
__attribute__((target("avx512f"))) void AddScaled8(double* acc, const double* x, double a,
                                                   std::size_t n) {
  AddScaledLanes<8>(acc, x, a, n);
}
__attribute__((target("avx512f"))) void AddSquared8(double* acc, const double* x, double a,
                                                    std::size_t n) {
  AddSquaredLanes<8>(acc, x, a, n);
}
__attribute__((target("avx512f"))) void AddSquaredDifference8(double* acc, const double* x,
                                                              const double* y, double a,
                                                              std::size_t n) {
  AddSquaredDifferenceLanes<8>(acc, x, y, a, n);
}
__attribute__((target("avx512f"))) void AddSquaredSum8(double* acc, const double* const* x,
                                                       const double* w, std::size_t m,
                                                       std::size_t n) {
  AddSquaredSumLanes<8>(acc, x, w, m, n);
}
__attribute__((target("avx512f"))) void BlendSquaredFloat8(double* m, double* shared,
                                                           const double* const* ind,
                                                           const double* scales, std::size_t r,
                                                           const WeightedFloatRows* inputs,
                                                           std::size_t count, std::size_t n) {
  BlendSquaredLanes<8>(m, shared, ind, scales, r, inputs, count, n);
}
__attribute__((target("avx512f"))) void SquaredDifferences8(double* acc, const double* const* x,
                                                            const double* y, const double* a,
                                                            std::size_t m, std::size_t n) {
  SquaredDifferencesLanes<8>(acc, x, y, a, m, n);
}
__attribute__((target("avx512f"))) void Sqrt8(double* x, std::size_t n) {
  std::size_t k = 0;
  for (; k + 8 <= n; k += 8) _mm512_storeu_pd(x + k, _mm512_sqrt_pd(_mm512_loadu_pd(x + k)));
  SqrtScalar(x + k, n - k);
}
#endif

Kernels PickKernels() {
#if defined(__x86_64__) && (defined(__GNUC__) || defined(__clang__))
  if (__builtin_cpu_supports("avx512f"))
    return {&AddScaled8, &AddSquared8,         &AddSquaredDifference8, &AddSquaredSum8,
            &Sqrt8,      &SquaredDifferences8, &BlendSquaredFloat8};
  if (__builtin_cpu_supports("avx2"))
    return {&AddScaled4, &AddSquared4,         &AddSquaredDifference4, &AddSquaredSum4,
            &Sqrt4,      &SquaredDifferences4, &BlendSquaredFloat4};
#endif
  return {&AddScaled2, &AddSquared2,         &AddSquaredDifference2, &AddSquaredSum2,
          &Sqrt2,      &SquaredDifferences2, &BlendSquaredFloat2};
}

const Kernels& Picked() {
  static const Kernels kernels = PickKernels();
  return kernels;
}

}  // namespace

void AddScaledBands(std::span<double> acc, std::span<const double> x, double a) {
  Picked().add_scaled(acc.data(), x.data(), a, acc.size());
}

void AddSquaredBands(std::span<double> acc, std::span<const double> x, double a) {
  Picked().add_squared(acc.data(), x.data(), a, acc.size());
}

void AddSquaredDifferenceBands(std::span<double> acc, std::span<const double> x,
                               std::span<const double> y, double a) {
  Picked().add_squared_difference(acc.data(), x.data(), y.data(), a, acc.size());
}

void AddSquaredSumBands(std::span<double> acc, std::span<const double* const> x,
                        std::span<const double> w) {
  if (w.empty()) return;
  Picked().add_squared_sum(acc.data(), x.data(), w.data(), w.size(), acc.size());
}

void BlendSquaredBands(std::span<double> measurement, std::span<double> shared,
                       std::span<const double* const> independent_rows,
                       std::span<const double> scales, std::span<const WeightedFloatRows> inputs) {
  Picked().blend_squared_float(measurement.data(), shared.empty() ? nullptr : shared.data(),
                               independent_rows.data(), scales.data(), independent_rows.size(),
                               inputs.data(), inputs.size(), measurement.size());
}

void SquaredDifferencesBands(std::span<double> acc, std::span<const double* const> x,
                             std::span<const double> y, std::span<const double> a) {
  Picked().squared_differences(acc.data(), x.data(), y.data(), a.data(), x.size(), acc.size());
}

void SqrtBands(std::span<double> x) {
  Picked().sqrt(x.data(), x.size());
}

}  // namespace brdf::uncertainty
