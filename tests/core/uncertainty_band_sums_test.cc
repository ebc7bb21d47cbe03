// core/uncertainty/band_sums: the vectorised sums across bands equal the scalar loops (to the
// last rounding; the square root exactly) for every length, the tail after the last full vector
// included, and touch no band beyond the accumulator.
#include <gtest/gtest.h>

#include <cmath>
#include <vector>

#include "core/uncertainty/band_sums.h"

namespace brdf::uncertainty {
namespace {

std::vector<double> Ramp(std::size_t n, double start, double step) {
  std::vector<double> v(n);
  for (std::size_t k = 0; k < n; ++k) v[k] = start + step * static_cast<double>(k) * (k % 3 + 1);
  return v;
}

// Lengths around every vector width (2, 4, 8) and the PR-650's and CS-2000's grids.
const std::size_t kLengths[] = {0, 1, 2, 3, 4, 5, 7, 8, 9, 15, 16, 17, 31, 101, 401};

// Within `relative` of the scalar loop's value: a fused multiply-add rounds once where the loop
// rounds twice, a last bit per operation.
void ExpectClose(const std::vector<double>& got, const std::vector<double>& want, std::size_t n,
                 double relative = 4e-16) {
  for (std::size_t k = 0; k < n; ++k) {
    EXPECT_NEAR(got[k], want[k], relative * std::abs(want[k])) << "band " << k << " of " << n;
  }
}

TEST(BandSums, AddScaledMatchesTheScalarLoop) {
  for (std::size_t n : kLengths) {
    std::vector<double> acc = Ramp(n + 1, 0.5, 0.01), want = acc;
    const std::vector<double> x = Ramp(n, -0.2, 0.003);
    AddScaledBands(std::span<double>(acc).first(n), x, 0.37);
    for (std::size_t k = 0; k < n; ++k) want[k] += 0.37 * x[k];
    ExpectClose(acc, want, n);
    EXPECT_EQ(acc[n], want[n]) << "the band after the accumulator changed (n = " << n << ")";
  }
}

TEST(BandSums, AddSquaredMatchesTheScalarLoop) {
  for (std::size_t n : kLengths) {
    std::vector<double> acc = Ramp(n + 1, 0.1, 0.02), want = acc;
    const std::vector<double> x = Ramp(n, -0.3, 0.007);
    AddSquaredBands(std::span<double>(acc).first(n), x, 0.0625);
    for (std::size_t k = 0; k < n; ++k) want[k] += 0.0625 * (x[k] * x[k]);
    ExpectClose(acc, want, n);
    EXPECT_EQ(acc[n], want[n]) << "the band after the accumulator changed (n = " << n << ")";
  }
}

TEST(BandSums, AddSquaredDifferenceMatchesTheScalarLoop) {
  for (std::size_t n : kLengths) {
    std::vector<double> acc = Ramp(n + 1, 0.0, 0.001), want = acc;
    const std::vector<double> x = Ramp(n, 1.0, 0.02), y = Ramp(n, 0.9, 0.025);
    AddSquaredDifferenceBands(std::span<double>(acc).first(n), x, y, 0.25);
    for (std::size_t k = 0; k < n; ++k) want[k] += 0.25 * ((x[k] - y[k]) * (x[k] - y[k]));
    ExpectClose(acc, want, n);
    EXPECT_EQ(acc[n], want[n]) << "the band after the accumulator changed (n = " << n << ")";
  }
}

TEST(BandSums, AddSquaredSumMatchesTheScalarLoopForOneToFiveInputs) {
  for (std::size_t n : kLengths) {
    const std::vector<std::vector<double>> x = {Ramp(n, 0.1, 0.01), Ramp(n, -0.2, 0.002),
                                                Ramp(n, 0.05, -0.003), Ramp(n, 0.3, 0.0),
                                                Ramp(n, -0.01, 0.02)};
    const std::vector<double> w = {0.3, 0.2, -0.1, 0.45, 0.15};
    for (std::size_t m = 1; m <= x.size(); ++m) {
      std::vector<const double*> rows;
      for (std::size_t i = 0; i < m; ++i) rows.push_back(x[i].data());
      std::vector<double> acc = Ramp(n + 1, 0.01, 0.001), want = acc;
      AddSquaredSumBands(std::span<double>(acc).first(n), rows, std::span(w).first(m));
      for (std::size_t k = 0; k < n; ++k) {
        double sum = 0;
        for (std::size_t i = 0; i < m; ++i) sum += w[i] * x[i][k];
        want[k] += sum * sum;
      }
      ExpectClose(acc, want, n, 2e-15);  // up to five products and a square, each a last bit
      EXPECT_EQ(acc[n], want[n]) << "the band after the accumulator changed (n = " << n << ")";
    }
  }
}

TEST(BandSums, SqrtIsStdSqrtInEveryBand) {
  for (std::size_t n : kLengths) {
    std::vector<double> x = Ramp(n + 1, 0.25, 0.013), want = x;
    SqrtBands(std::span<double>(x).first(n));
    for (std::size_t k = 0; k < n; ++k) {
      EXPECT_EQ(x[k], std::sqrt(want[k])) << "band " << k << " of " << n;  // correctly rounded
    }
    EXPECT_EQ(x[n], want[n]) << "the band after the span changed (n = " << n << ")";
  }
}

}  // namespace
}  // namespace brdf::uncertainty
