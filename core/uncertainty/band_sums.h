// Sums across a spectrum's bands, the inner loops of an interpolated value's uncertainty
// (blend.h): each adds one vertex's or one component's spectrum into an accumulator, band by
// band, several bands at once (AVX-512 or AVX2 where the processor has them, else SSE2; chosen
// once at start-up). The results equal the scalar loops' up to the last bit of rounding (a fused
// multiply-add may round once where the scalar code rounds twice).
// Each span is the accumulator's size (the caller checks). Pure: no I/O.
#pragma once

#include <cstddef>
#include <span>

namespace brdf::uncertainty {

// acc[k] += a · x[k]
void AddScaledBands(std::span<double> acc, std::span<const double> x, double a);

// acc[k] += a · x[k]²
void AddSquaredBands(std::span<double> acc, std::span<const double> x, double a);

// acc[k] += a · (x[k] − y[k])²
void AddSquaredDifferenceBands(std::span<double> acc, std::span<const double> x,
                               std::span<const double> y, double a);

// acc[k] += (Σᵢ w[i] · x[i][k])², i < w.size() == x.size() ≥ 1, each x[i] of acc.size() values:
// one shared input's blend (its contributions from several vertices, weighted) squared, in one
// pass over the bands.
void AddSquaredSumBands(std::span<double> acc, std::span<const double* const> x,
                        std::span<const double> w);

// One shared input of a blend (blend.h): its contributions from `count` ≥ 1 vertices, each a row
// of floats (a BlendBudget's, blend_budget.h) of the accumulator's size, with their weights.
struct WeightedFloatRows {
  const float* const* rows = nullptr;
  const double* weights = nullptr;
  std::size_t count = 0;
};

// A blend's measurement² in one pass over the bands, the same values to the last bit as
//   independent = 0;  AddSquaredBands(independent, independent_rows[r], scales[r]) for each r;
//   s = 0;  AddSquaredSumBands(s, input.rows widened to double, input.weights) for each input,
//   in order;  measurement = s;  AddScaledBands(measurement, independent, 1.0);
// (the same operations on each band in the same order, each float widened as it is read, without
// the accumulators' trips through memory between them): measurement[k] = s[k] + independent[k],
// and shared[k] = s[k] unless `shared` is empty. independent_rows.size() == scales.size(); every
// row of measurement's size.
void BlendSquaredBands(std::span<double> measurement, std::span<double> shared,
                       std::span<const double* const> independent_rows,
                       std::span<const double> scales, std::span<const WeightedFloatRows> inputs);

// acc = 0, then AddSquaredDifferenceBands(acc, x[i], y, a[i]) for each i in order, in one pass
// over the bands (the same values to the last bit). x.size() == a.size(); every x[i] and y of
// acc's size.
void SquaredDifferencesBands(std::span<double> acc, std::span<const double* const> x,
                             std::span<const double> y, std::span<const double> a);

// x[k] = sqrt(x[k]) (correctly rounded, as std::sqrt; a negative x[k] gives NaN).
void SqrtBands(std::span<double> x);

}  // namespace brdf::uncertainty
