// Sums across a spectrum's bands, the inner loops of an interpolated value's uncertainty
// (blend.h): each adds one vertex's or one component's spectrum into an accumulator, band by
// band, several bands at once (AVX-512 or AVX2 where the processor has them, else SSE2; chosen
// once at start-up). The results equal the scalar loops' up to the last bit of rounding (a fused
// multiply-add may round once where the scalar code rounds twice).
// Each span is the accumulator's size (the caller checks). Pure: no I/O.
#pragma once

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

// x[k] = sqrt(x[k]) (correctly rounded, as std::sqrt; a negative x[k] gives NaN).
void SqrtBands(std::span<double> x);

}  // namespace brdf::uncertainty
