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

// The one-pass sums give the bits of the calls they replace (blend.h's former loops), for every
// length and any number of readings and inputs.
TEST(BandSums, BlendSquaredIsTheSeparateSumsBitForBit) {
  for (std::size_t n : kLengths) {
    std::vector<std::vector<double>> rows;
    for (int r = 0; r < 9; ++r) rows.push_back(Ramp(n, 0.01 * (r + 1), 0.0013 * (r % 4 - 1.5)));
    const std::vector<double> w = {0.31, 0.27, 0.19, 0.23, 0.11};
    for (std::size_t readings = 0; readings <= 4; ++readings) {
      std::vector<const double*> independent;
      std::vector<double> scales;
      for (std::size_t i = 0; i < readings; ++i) {
        independent.push_back(rows[i].data());
        scales.push_back(w[i] * w[i]);
      }
      // Inputs of 1, 2, 3 and 4 vertices' contributions, held as floats (a BlendBudget's rows);
      // the separate sums read the same floats widened to double.
      const std::vector<std::vector<int>> input_of = {{4}, {5, 6}, {7, 8, 0}, {1, 3, 5, 7}};
      std::vector<std::vector<float>> float_rows;
      std::vector<std::vector<double>> widened;
      for (const auto& r : rows) {
        float_rows.emplace_back(r.begin(), r.end());
        widened.emplace_back(float_rows.back().begin(), float_rows.back().end());
      }
      std::vector<std::vector<const float*>> input_rows;
      std::vector<std::vector<const double*>> widened_rows;
      for (const auto& in : input_of) {
        input_rows.emplace_back();
        widened_rows.emplace_back();
        for (int r : in) {
          input_rows.back().push_back(float_rows[r].data());
          widened_rows.back().push_back(widened[r].data());
        }
      }
      std::vector<WeightedFloatRows> inputs;
      for (const auto& in : input_rows) inputs.push_back({in.data(), w.data(), in.size()});
      std::vector<double> independent_sum(n, 0.0), shared_want(n, 0.0);
      for (std::size_t i = 0; i < readings; ++i) {
        AddSquaredBands(independent_sum, std::span(independent[i], n), scales[i]);
      }
      for (const auto& in : widened_rows) {
        AddSquaredSumBands(shared_want, in, std::span(w).first(in.size()));
      }
      std::vector<double> measurement_want = shared_want;
      AddScaledBands(measurement_want, independent_sum, 1.0);
      std::vector<double> measurement(n + 1, -1.0), shared(n + 1, -1.0);
      BlendSquaredBands(std::span(measurement).first(n), std::span(shared).first(n), independent,
                        scales, inputs);
      for (std::size_t k = 0; k < n; ++k) {
        EXPECT_EQ(measurement[k], measurement_want[k]) << "band " << k << " of " << n;
        EXPECT_EQ(shared[k], shared_want[k]) << "band " << k << " of " << n;
      }
      EXPECT_EQ(measurement[n], -1.0);
      EXPECT_EQ(shared[n], -1.0);
      // Without the shared part kept: the same measurement.
      std::vector<double> alone(n, -1.0);
      BlendSquaredBands(alone, {}, independent, scales, inputs);
      for (std::size_t k = 0; k < n; ++k) EXPECT_EQ(alone[k], measurement_want[k]);
    }
  }
}

TEST(BandSums, SquaredDifferencesIsTheSeparateSumsBitForBit) {
  for (std::size_t n : kLengths) {
    const std::vector<double> y = Ramp(n, 0.9, 0.025);
    std::vector<std::vector<double>> x;
    for (int i = 0; i < 5; ++i) x.push_back(Ramp(n, 1.0 - 0.07 * i, 0.02 + 0.003 * i));
    const std::vector<double> a = {0.4, 0.1, 0.25, 0.2, 0.05};
    for (std::size_t m = 0; m <= x.size(); ++m) {
      std::vector<const double*> rows;
      for (std::size_t i = 0; i < m; ++i) rows.push_back(x[i].data());
      std::vector<double> want(n, 0.0);
      for (std::size_t i = 0; i < m; ++i) AddSquaredDifferenceBands(want, x[i], y, a[i]);
      std::vector<double> got(n + 1, -1.0);
      SquaredDifferencesBands(std::span(got).first(n), rows, y, std::span(a).first(m));
      for (std::size_t k = 0; k < n; ++k) EXPECT_EQ(got[k], want[k]) << "band " << k;
      EXPECT_EQ(got[n], -1.0);
    }
  }
}

}  // namespace
}  // namespace brdf::uncertainty
