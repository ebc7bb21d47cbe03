#include "core/interp/octant.h"

#include <array>

#include "core/interp/kd_tree.h"
#include "core/interp/octant_cube.h"
#include "core/interp/point_cloud.h"

namespace brdf::interp {
namespace {

class OctantInterpolator final : public Interpolator {
 public:
  OctantInterpolator(std::shared_ptr<const SampleSet> samples, PointCloud cloud)
      : samples_(std::move(samples)), cloud_(std::move(cloud)), tree_(cloud_) {}

  Method method() const override { return Method::kOctant; }
  int dims() const override { return cloud_.dims; }

  Interpolation Evaluate(std::span<const double> query) const override {
    const int d = cloud_.dims;
    if (!ValidQuery(query, d)) {
      return InvalidQueryAnswer(Method::kOctant, InterpStatus::kEmptyOctant, query, d);
    }
    std::array<double, kMaxDims> p{};
    cloud_.ScaleQuery(query, p);
    OrthantWinners winners;
    tree_.NearestPerOrthant(p.data(), winners);
    return AssembleOctantAnswer(cloud_, *samples_, winners,
                                std::span(p.data(), static_cast<std::size_t>(d)));
  }

 private:
  std::shared_ptr<const SampleSet> samples_;
  PointCloud cloud_;
  KdTree tree_;
};

}  // namespace

Result<std::unique_ptr<Interpolator>> MakeOctantInterpolator(
    std::shared_ptr<const SampleSet> samples, const Options& options) {
  if (samples == nullptr) return InvalidArgument("octant interpolator: no sample set (null)");
  Result<PointCloud> cloud = BuildPointCloud(*samples, options);
  if (!cloud.ok()) return cloud.status().WithContext("octant interpolator");
  return std::unique_ptr<Interpolator>(
      std::make_unique<OctantInterpolator>(std::move(samples), std::move(cloud).value()));
}

}  // namespace brdf::interp
