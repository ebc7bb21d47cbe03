#include "core/interp/barycentric.h"

#include <cmath>

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
  Column r{};
  double hadamard = 1.0;
  for (int k = 0; k < dims; ++k) {
    double len2 = 0.0;
    for (int j = 0; j < dims; ++j) {
      edges[k][j] = vertices[k + 1][j] - vertices[0][j];
      len2 += edges[k][j] * edges[k][j];
    }
    hadamard *= std::sqrt(len2);
  }
  for (int j = 0; j < dims; ++j) r[j] = p[j] - vertices[0][j];

  std::array<const Column*, 4> cols{&edges[0], &edges[1], &edges[2], &edges[3]};
  const double det = Det(cols, dims);
  if (!(std::fabs(det) > kDegenerateRelativeVolume * hadamard)) return out;  // also NaN

  std::array<double, kMaxSimplexVertices> lambda{};
  double sum_mu = 0.0;
  for (int k = 0; k < dims; ++k) {
    cols[k] = &r;
    lambda[k + 1] = Det(cols, dims) / det;
    cols[k] = &edges[k];
    sum_mu += lambda[k + 1];
  }
  lambda[0] = 1.0 - sum_mu;

  out.fit = SimplexFit::kOutside;
  for (int k = 0; k <= dims; ++k) {
    if (!(lambda[k] >= -kEnclosingTolerance)) return out;
  }
  double total = 0.0;
  for (int k = 0; k <= dims; ++k) {
    lambda[k] = lambda[k] > 0.0 ? lambda[k] : 0.0;
    total += lambda[k];
  }
  for (int k = 0; k <= dims; ++k) out.weights[k] = lambda[k] / total;
  out.fit = SimplexFit::kEncloses;
  return out;
}

void BlendSpectra(std::span<const double> weights, std::span<const double* const> spectra,
                  std::span<double> out) {
  // One pass over all vertex spectra (their memory streams in parallel). Each band is summed as
  // ((w0·s0 + w1·s1) + w2·s2) + …, the same order for every vertex count.
  const std::size_t bands = out.size();
  const double* s0 = spectra[0];
  const double w0 = weights[0];
  switch (weights.size()) {
    case 4: {
      const double *s1 = spectra[1], *s2 = spectra[2], *s3 = spectra[3];
      const double w1 = weights[1], w2 = weights[2], w3 = weights[3];
      for (std::size_t b = 0; b < bands; ++b) {
        out[b] = w0 * s0[b] + w1 * s1[b] + w2 * s2[b] + w3 * s3[b];
      }
      return;
    }
    case 5: {
      const double *s1 = spectra[1], *s2 = spectra[2], *s3 = spectra[3], *s4 = spectra[4];
      const double w1 = weights[1], w2 = weights[2], w3 = weights[3], w4 = weights[4];
      for (std::size_t b = 0; b < bands; ++b) {
        out[b] = w0 * s0[b] + w1 * s1[b] + w2 * s2[b] + w3 * s3[b] + w4 * s4[b];
      }
      return;
    }
    default:
      for (std::size_t b = 0; b < bands; ++b) out[b] = w0 * s0[b];
      for (std::size_t k = 1; k < weights.size(); ++k) {
        const double w = weights[k];
        const double* s = spectra[k];
        for (std::size_t b = 0; b < bands; ++b) out[b] += w * s[b];
      }
  }
}

}  // namespace brdf::interp
