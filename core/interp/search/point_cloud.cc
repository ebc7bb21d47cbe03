#include "core/interp/search/point_cloud.h"

#include <cmath>
#include <string>

namespace brdf::interp {
namespace {

std::string AxisNames(int dims) {
  return dims == 3 ? "(θi, θo, φ)" : "(θi, φi, θo, φo)";
}

}  // namespace

Status ValidateOptions(const Options& options, int dims) {
  if (dims != 3 && dims != 4) {
    return InvalidArgument("interpolation needs 3D (θi, θo, φ) or 4D (θi, φi, θo, φo) data, not " +
                           std::to_string(dims) + "D");
  }
  if (options.coordinates != Coordinates::kIncidence) {
    return InvalidArgument(
        "option coordinates half_difference: build the interpolator with MakeInterpolator, "
        "which maps the samples to (θh, θd, φd) first");
  }
  if (!options.axis_scale.empty()) {
    if (options.axis_scale.size() != static_cast<std::size_t>(dims)) {
      return InvalidArgument("option axis_scale has " + std::to_string(options.axis_scale.size()) +
                             " values; the data has " + std::to_string(dims) + " coordinates " +
                             AxisNames(dims) + ": give one multiplier per axis, or none");
    }
    for (std::size_t j = 0; j < options.axis_scale.size(); ++j) {
      const double s = options.axis_scale[j];
      if (!std::isfinite(s) || !(s > 0)) {
        return InvalidArgument("option axis_scale: value " + std::to_string(j) + " (" +
                               std::to_string(s) +
                               ") is not a finite positive number; every multiplier must be > 0");
      }
    }
  }
  if (dims == 4 && options.mirror_phi) {
    return InvalidArgument(
        "option mirror_phi applies to isotropic (3D) data only; 4D (anisotropic) samples are not "
        "symmetric in φ: turn it off");
  }
  if (dims == 4 && options.reciprocity) {
    return InvalidArgument(
        "option reciprocity is implemented for isotropic (3D) data only: turn it off for 4D data");
  }
  return Status::Ok();
}

std::size_t ImageCount(const Options& options) {
  return (options.mirror_phi ? 3 : 1) * (options.reciprocity ? 2 : 1);
}

Result<PointCloud> BuildPointCloud(const SampleSet& samples, const Options& options) {
  BRDF_RETURN_IF_ERROR(ValidateOptions(options, samples.dims()));
  if (samples.size() == 0) {
    return InvalidArgument("the sample set is empty: interpolation needs at least one sample");
  }
  return BuildPointCloudTail(samples, options, 0);
}

Result<PointCloud> BuildPointCloudTail(const SampleSet& samples, const Options& options,
                                       std::size_t first) {
  BRDF_RETURN_IF_ERROR(ValidateOptions(options, samples.dims()));
  if (first > samples.size()) {
    return InvalidArgument("point cloud: samples from " + std::to_string(first) +
                           " asked of a set of " + std::to_string(samples.size()) +
                           "; the first sample must be within the set");
  }
  const int dims = samples.dims();
  const auto d = static_cast<std::size_t>(dims);
  PointCloud cloud;
  cloud.dims = dims;
  cloud.scale = options.axis_scale.empty() ? std::vector<double>(d, 1.0) : options.axis_scale;

  const std::size_t copies = ImageCount(options);
  const std::size_t n = samples.size();
  cloud.coords.reserve((n - first) * copies * d);
  cloud.sample.reserve((n - first) * copies);

  // One block per image; swap: θi ↔ θo; mirror: φ → −φ (0 − φ, so that φ = 0 stays +0), or
  // φ → 360° − φ (the copy beyond 180° that fills the specular side).
  enum class Phi { kSame, kNegated, kFromFullTurn };
  auto add_block = [&](bool swap, Phi mirror) {
    for (std::size_t i = first; i < n; ++i) {
      const auto c = samples.coords(i);
      if (dims == 3) {
        cloud.coords.push_back(swap ? c[1] : c[0]);
        cloud.coords.push_back(swap ? c[0] : c[1]);
        cloud.coords.push_back(mirror == Phi::kNegated        ? 0.0 - c[2]
                               : mirror == Phi::kFromFullTurn ? 360.0 - c[2]
                                                              : c[2]);
      } else {
        cloud.coords.insert(cloud.coords.end(), c.begin(), c.end());
      }
      cloud.sample.push_back(static_cast<std::uint32_t>(i));
    }
  };
  for (const bool swap : {false, true}) {
    if (swap && !options.reciprocity) break;
    add_block(swap, Phi::kSame);
    if (options.mirror_phi) {
      add_block(swap, Phi::kNegated);
      add_block(swap, Phi::kFromFullTurn);
    }
  }

  cloud.scaled.resize(cloud.coords.size());
  for (std::size_t k = 0; k < cloud.coords.size(); ++k) {
    cloud.scaled[k] = cloud.coords[k] * cloud.scale[k % d];
  }
  return cloud;
}

}  // namespace brdf::interp
