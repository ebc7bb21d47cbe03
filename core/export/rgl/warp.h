// The piecewise-bilinear 2D distribution that readers of the RGL material format (rgl/writer.h)
// build from its tables: values on a regular nx × ny grid over the unit square, interpolated
// bilinearly, optionally conditioned on up to three parameters (φi, θi, wavelength) at which the
// 2D slices are tabulated and between which values are blended linearly. With a CDF it maps the
// unit square onto itself in proportion to the values (Sample) and back (Invert): a marginal
// distribution over rows, then a conditional one over columns. Our own code, written from the
// description in docs/rgl-format.md (after Dupuy & Jakob 2018 and the readers of Mitsuba 3 and
// pbrt-v4); computed in single precision as they do, so that values agree to float rounding.
// Pure.
#pragma once

#include <cstddef>
#include <vector>

namespace brdf::exports {

struct WarpPoint {
  float x = 0, y = 0;
  float pdf = 0;  // density over the unit square (Sample, Invert); 0 from Eval
};

class Warp2D {
 public:
  Warp2D() = default;
  // `data`: one nx × ny slice (x fastest) per combination of parameter values, the first
  // parameter outermost. `params[d]` the values of parameter d (increasing; 1 value: constant).
  // normalize: scale each slice to integrate to 1 over the unit square (a density); build_cdf
  // (implies normalize): also make Sample and Invert work. Without either, Eval gives the values
  // themselves, bilinearly interpolated. nx, ny ≥ 2.
  Warp2D(std::size_t nx, std::size_t ny, const float* data, std::vector<std::vector<float>> params,
         bool normalize, bool build_cdf);

  // The (normalised) value at `pos` in [0, 1]², for parameter values `param` (one per parameter).
  float Eval(float x, float y, const float* param) const;
  // Warps a uniform point of the unit square; pdf is the density of the result.
  WarpPoint Sample(float x, float y, const float* param) const;
  // Inverse of Sample; pdf is the density at the given point.
  WarpPoint Invert(float x, float y, const float* param) const;

  std::size_t nx() const { return nx_; }
  std::size_t ny() const { return ny_; }

 private:
  struct Blend {  // a parameter point: first slice and the linear weights per parameter
    std::size_t slice = 0;
    float w[3][2] = {{1, 0}, {1, 0}, {1, 0}};
  };
  Blend BlendAt(const float* param) const;
  // Value at index i of a slice of `slice_size` entries, blended over the parameter corners.
  float Lookup(const std::vector<float>& table, std::size_t i, std::size_t slice_size,
               const Blend& b) const;

  std::size_t nx_ = 0, ny_ = 0;
  std::vector<std::vector<float>> params_;
  std::vector<std::size_t> strides_;  // in slices; 0 for a parameter with one value
  std::vector<float> data_;
  std::vector<float> marginal_cdf_;     // ny per slice
  std::vector<float> conditional_cdf_;  // nx × ny per slice
};

}  // namespace brdf::exports
