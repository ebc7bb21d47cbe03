#include "core/interp/octant/reference.h"

#include <array>
#include <limits>

#include "core/interp/octant/cube.h"
#include "core/interp/search/point_cloud.h"

namespace brdf::interp {
namespace {

class OctantReferenceInterpolator final : public Interpolator {
 public:
  OctantReferenceInterpolator(std::shared_ptr<const SampleSet> samples, PointCloud cloud)
      : samples_(std::move(samples)), cloud_(std::move(cloud)) {}

  Method method() const override { return Method::kOctant; }
  int dims() const override { return cloud_.dims; }
  std::size_t HeapBytes() const override { return sizeof(*this) + cloud_.HeapBytes(); }

  Interpolation Evaluate(std::span<const double> query) const override {
    const int d = cloud_.dims;
    if (!ValidQuery(query, d)) {
      return InvalidQueryAnswer(Method::kOctant, InterpStatus::kEmptyOctant, query, d);
    }
    std::array<double, kMaxDims> p{};
    cloud_.ScaleQuery(query, p);

    // The paper's step 2, literally: one pass over all points in rank order. A point replaces
    // its orthant's best only when strictly nearer, so among equals the lowest rank stays (the
    // second clause only admits the first point of an orthant at an infinite distance).
    std::array<double, kMaxOrthants> best_d2{};
    best_d2.fill(std::numeric_limits<double>::infinity());
    OrthantWinners winners;
    winners.rank.fill(kNoPoint);
    winners.scaled.fill(nullptr);
    for (std::size_t r = 0; r < cloud_.size(); ++r) {
      const double* x = cloud_.scaled_point(r).data();
      const auto o = static_cast<std::size_t>(OrthantOf(x, p.data(), d));
      const double d2 = SquaredDistance(x, p.data(), d);
      if (d2 < best_d2[o] || (d2 == best_d2[o] && winners.rank[o] == kNoPoint)) {
        best_d2[o] = d2;
        winners.rank[o] = static_cast<std::uint32_t>(r);
        winners.scaled[o] = x;
      }
    }
    return AssembleOctantAnswer(cloud_, *samples_, winners,
                                std::span(p.data(), static_cast<std::size_t>(d)));
  }

 private:
  std::shared_ptr<const SampleSet> samples_;
  PointCloud cloud_;
};

}  // namespace

Result<std::unique_ptr<Interpolator>> MakeOctantReferenceInterpolator(
    std::shared_ptr<const SampleSet> samples, const Options& options) {
  if (samples == nullptr) {
    return InvalidArgument("octant reference interpolator: no sample set (null)");
  }
  Result<PointCloud> cloud = BuildPointCloud(*samples, options);
  if (!cloud.ok()) return cloud.status().WithContext("octant reference interpolator");
  return std::unique_ptr<Interpolator>(
      std::make_unique<OctantReferenceInterpolator>(std::move(samples), std::move(cloud).value()));
}

}  // namespace brdf::interp
