// The point set an interpolation method actually searches: the measured samples, then their
// symmetry copies (Options.mirror_phi, Options.reciprocity), with every coordinate multiplied by
// Options.axis_scale. All methods see the same cloud, so they agree on what "nearest" and "ties go
// to the earlier sample" mean. Pure: no I/O.
#pragma once

#include <cstddef>
#include <cstdint>
#include <span>
#include <vector>

#include "core/interp/interpolator.h"
#include "core/status.h"

namespace brdf::interp {

// Checks `options` for data of `dims` coordinates. Errors (kInvalidArgument) name the option:
// coordinates other than incidence (only MakeInterpolator maps to half/difference angles);
// axis_scale of the wrong length or with a value that is not finite and positive; mirror_phi or
// reciprocity on 4D (anisotropic) data, where they are not symmetries.
Status ValidateOptions(const Options& options, int dims);

// A point's rank is its position in the cloud: measured samples first, in SampleSet order
// (rank i = sample i), then one block of copies per symmetry, each block in sample order:
//   mirror_phi only:        (θi, θo, −φ), then (θi, θo, 360° − φ)
//   reciprocity only:       (θo, θi, φ)
//   both:                   (θi, θo, −φ), (θi, θo, 360° − φ), then (θo, θi, φ), (θo, θi, −φ),
//                           (θo, θi, 360° − φ)
// (all of them are exact for isotropic data: φ and −φ are the same relative azimuth, and so are
// −φ and 360° − φ; the copy beyond 180° is the one that encloses queries near the specular plane).
// Rank is the tie-breaker: of two points at the same distance the lower rank wins, so a measured
// sample always beats a copy. Copies that coincide with their original are kept: they can never
// win.
struct PointCloud {
  int dims = 0;
  std::vector<double> scale;          // dims multipliers (all 1 when axis_scale is empty)
  std::vector<double> coords;         // size() × dims, unscaled: the point's own coordinates
  std::vector<double> scaled;         // size() × dims: coords[j] * scale[j], one multiplication
  std::vector<std::uint32_t> sample;  // size(): the SampleSet index the point copies

  std::size_t size() const { return sample.size(); }
  // Heap of the four arrays (for memory bounds).
  std::size_t HeapBytes() const {
    return (scale.capacity() + coords.capacity() + scaled.capacity()) * sizeof(double) +
           sample.capacity() * sizeof(std::uint32_t);
  }
  std::span<const double> point(std::size_t rank) const {
    return {coords.data() + rank * static_cast<std::size_t>(dims), static_cast<std::size_t>(dims)};
  }
  std::span<const double> scaled_point(std::size_t rank) const {
    return {scaled.data() + rank * static_cast<std::size_t>(dims), static_cast<std::size_t>(dims)};
  }
  // The query in the cloud's (scaled) space: query[j] * scale[j].
  void ScaleQuery(std::span<const double> query, std::span<double> out) const {
    for (std::size_t j = 0; j < scale.size(); ++j) out[j] = query[j] * scale[j];
  }
};

// a * b, rounded to a double before anything is added to it: a compiler allowed to fuse
// multiply-adds (-ffp-contract=fast with FMA available) must not fuse it into a sum, or two
// computations of "the same" expression could differ in the last bit (a tie decided differently,
// a blended band off by one ulp). Free on x86 and ARM (an empty asm pins the value).
inline double RoundedProduct(double a, double b) {
  double s = a * b;
#if defined(__GNUC__) && (defined(__x86_64__) || defined(__i386__))
  asm("" : "+x"(s));
#elif defined(__GNUC__) && defined(__aarch64__)
  asm("" : "+w"(s));
#else
  volatile double pinned = s;
  s = pinned;
#endif
  return s;
}
inline double RoundedSquare(double d) {
  return RoundedProduct(d, d);
}

// Squared Euclidean distance in the cloud's scaled space, ((0 + d0²) + d1²) + d2² (+ d3²): summed
// in axis order. Every search uses this one definition (the vector kernels of search/kd_tree.cc
// compute the same operations lane by lane), so "nearest" and "tie" mean the same thing bit for bit
// in all of them.
template <int D>
inline double SquaredDistance(const double* a, const double* b) {
  double sum = 0.0;
#pragma GCC unroll 4
  for (int j = 0; j < D; ++j) sum += RoundedSquare(a[j] - b[j]);
  return sum;
}
inline double SquaredDistance(const double* a, const double* b, int dims) {
  return dims == 3 ? SquaredDistance<3>(a, b) : SquaredDistance<4>(a, b);
}

// Errors: a SampleSet that is empty or not 3D/4D, and everything ValidateOptions rejects.
Result<PointCloud> BuildPointCloud(const SampleSet& samples, const Options& options);

// How many images of each sample the cloud holds: 1, ×3 with mirror_phi, ×2 with reciprocity.
std::size_t ImageCount(const Options& options);

// The part of BuildPointCloud(samples, options) that samples [first, samples.size()) contribute,
// in the same layout (one block per image, each in sample order) with the same values bit for
// bit; `sample` holds SampleSet indices (first, first + 1, …). Point k of the result is sample
// first + k % m of image k / m (m = samples.size() − first), whose rank in the full cloud is
// (k / m) · samples.size() + first + k % m. May be empty (first == samples.size()).
// Errors: as BuildPointCloud, except that an empty range is not one; first > size() is.
Result<PointCloud> BuildPointCloudTail(const SampleSet& samples, const Options& options,
                                       std::size_t first);

}  // namespace brdf::interp
