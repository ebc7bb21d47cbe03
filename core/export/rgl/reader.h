// A reader of RGL material files (rgl/writer.h, docs/rgl-format.md) that evaluates the BRDF the
// way Mitsuba 3's `measured` BSDF and pbrt-v4's MeasuredBxDF do: the half vector is mapped to
// the unit square, inverted through the visible-normal warp, the stored values are interpolated
// there (bilinearly, and linearly in θi and wavelength), multiplied by D / (4σ) and — because
// they carry the outgoing cosine — divided by cos θo. Used by tests to check our files. Pure:
// parses bytes.
#pragma once

#include <cstdint>
#include <map>
#include <string>
#include <string_view>
#include <vector>

#include "core/export/rgl/warp.h"
#include "core/pose.h"
#include "core/status.h"

namespace brdf::exports {

struct RglTensor {
  std::uint8_t dtype = 0;  // 1 uint8, 10 float32 (the only ones read here)
  std::vector<std::uint64_t> shape;
  std::vector<float> f32;
  std::vector<std::uint8_t> u8;
};

// The fields of a tensor_file. kInvalidArgument naming what is wrong (header, version, a field
// past the end, an unsupported dtype).
Result<std::map<std::string, RglTensor>> ParseTensorFile(std::string_view bytes);

class RglMaterial {
 public:
  // Checks the fields and shapes the readers check. kInvalidArgument naming the field.
  static Result<RglMaterial> Parse(std::string_view bytes);

  bool rgb() const { return rgb_; }
  const std::vector<float>& wavelengths() const { return wavelengths_; }  // empty for RGB
  std::size_t channels() const { return channels_; }
  const std::string& description() const { return description_; }

  // f (sr⁻¹) per channel for directions in the sample frame (degrees); 0 below the surface.
  std::vector<double> Brdf(const Directions& d) const;
  // The stored values times D/(4σ): f · cos θo, what a renderer's eval returns.
  std::vector<double> BrdfCosine(const Directions& d) const;

 private:
  bool rgb_ = false, isotropic_ = true, jacobian_ = true;
  std::size_t channels_ = 0;
  std::string description_;
  std::vector<float> wavelengths_;
  Warp2D ndf_, sigma_, vndf_, values_;
};

}  // namespace brdf::exports
