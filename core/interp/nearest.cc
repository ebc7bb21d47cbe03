#include "core/interp/nearest.h"

#include <algorithm>
#include <array>

#include "core/interp/octant/cube.h"
#include "core/interp/search/kd_tree.h"
#include "core/interp/search/point_cloud.h"

namespace brdf::interp {
namespace {

class NearestInterpolator final : public Interpolator {
 public:
  NearestInterpolator(std::shared_ptr<const SampleSet> samples, PointCloud cloud)
      : samples_(std::move(samples)),
        cloud_(std::move(cloud)),
        tree_(cloud_, KdTree::Kernel::kBest, KdTree::Search::kTree) {}

  Method method() const override { return Method::kNearest; }
  int dims() const override { return cloud_.dims; }
  std::size_t HeapBytes() const override {
    return sizeof(*this) + cloud_.HeapBytes() + tree_.HeapBytes();
  }

  InterpStatus SpectrumAt(std::span<const double> query,
                          std::span<double> spectrum) const override {
    const int d = cloud_.dims;
    if (!ValidQuery(query, d)) return InterpStatus::kOutsideHull;
    std::array<double, kMaxDims> p{};
    cloud_.ScaleQuery(query, p);
    const auto s = samples_->spectrum(cloud_.sample[tree_.Nearest(p.data())]);
    std::copy_n(s.begin(), std::min(s.size(), spectrum.size()), spectrum.begin());
    return InterpStatus::kOk;
  }

  Interpolation Evaluate(std::span<const double> query) const override {
    const int d = cloud_.dims;
    if (!ValidQuery(query, d)) {
      return InvalidQueryAnswer(Method::kNearest, InterpStatus::kOutsideHull, query, d);
    }
    std::array<double, kMaxDims> p{};
    cloud_.ScaleQuery(query, p);
    const std::uint32_t rank = tree_.Nearest(p.data());
    const std::uint32_t index = cloud_.sample[rank];

    Interpolation out;
    out.method = Method::kNearest;
    out.status = InterpStatus::kOk;
    const auto spectrum = samples_->spectrum(index);
    out.spectrum.assign(spectrum.begin(), spectrum.end());
    Vertex& v = out.vertices.emplace_back();
    v.id = samples_->id(index);
    v.index = index;
    const auto coords = cloud_.point(rank);
    v.coords.assign(coords.begin(), coords.end());
    v.weight = 1.0;
    return out;
  }

 private:
  std::shared_ptr<const SampleSet> samples_;
  PointCloud cloud_;  // before tree_, which points into it
  KdTree tree_;
};

}  // namespace

Result<std::unique_ptr<Interpolator>> MakeNearestInterpolator(
    std::shared_ptr<const SampleSet> samples, const Options& options) {
  if (samples == nullptr) return InvalidArgument("nearest interpolator: no sample set (null)");
  Result<PointCloud> cloud = BuildPointCloud(*samples, options);
  if (!cloud.ok()) return cloud.status().WithContext("nearest interpolator");
  return std::unique_ptr<Interpolator>(
      std::make_unique<NearestInterpolator>(std::move(samples), std::move(cloud).value()));
}

}  // namespace brdf::interp
