#include "core/interp/delaunay/near.h"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <limits>
#include <utility>
#include <vector>

#include "core/interp/barycentric.h"
#include "core/interp/delaunay/cgal.h"
#include "core/interp/delaunay/locate.h"
#include "core/interp/delaunay/qhull.h"
#include "core/interp/search/point_cloud.h"

namespace brdf::interp {
namespace {

// The first neighbourhood tried, and how much larger each next one is.
constexpr std::size_t kFirstPoints = 64;
constexpr std::size_t kGrowth = 4;
// Outside the hull of all points, proved by a plane with every point at most kOnPlane (of the
// bounding box's diagonal: rounding) beyond it and the query more than kBeyond beyond it: then
// the query is farther from the hull than the locator's tolerance (a barycentric coordinate of
// -1e-10, locate.cc's kHullEps) could reach, and the whole triangulation finds it outside too.
constexpr double kOnPlane = 1e-9;
constexpr double kBeyond = 1e-7;

}  // namespace

NearDelaunay::NearDelaunay(std::shared_ptr<const SampleSet> samples, DistinctCloud cloud)
    : samples_(std::move(samples)), cloud_(std::move(cloud)), hull_(std::make_unique<Hull>()) {
  lower_.fill(std::numeric_limits<double>::infinity());
  upper_.fill(-std::numeric_limits<double>::infinity());
  for (std::size_t p = 0; p < cloud_.size(); ++p) {
    const auto x = cloud_.scaled_point(p);
    for (std::size_t i = 0; i < 3; ++i) {
      lower_[i] = std::min(lower_[i], x[i]);
      upper_[i] = std::max(upper_[i], x[i]);
    }
  }
  double diagonal2 = 0;
  for (std::size_t i = 0; i < 3; ++i) {
    diagonal2 += (upper_[i] - lower_[i]) * (upper_[i] - lower_[i]);
  }
  diagonal_ = std::sqrt(diagonal2);
}

Result<NearDelaunay> NearDelaunay::Create(std::shared_ptr<const SampleSet> samples,
                                          const Options& options) {
  if (samples == nullptr) return InvalidArgument("Delaunay near a query: no sample set given");
  if (samples->dims() != 3) {
    return InvalidArgument("Delaunay near a query: 3D (isotropic) samples only, got " +
                           std::to_string(samples->dims()) + "D");
  }
  if (options.coordinates != Coordinates::kIncidence || options.trend != Trend::kNone) {
    // MakeInterpolator answers these through another interpolator wrapped around the method.
    return InvalidArgument(
        "Delaunay near a query: incidence coordinates without a trend only (the options ask "
        "for half/difference coordinates or a trend)");
  }
  Result<DistinctCloud> cloud = DistinctDelaunayPoints(*samples, options);
  if (!cloud.ok()) return cloud.status().WithContext("Delaunay near a query");
  return NearDelaunay(std::move(samples), std::move(*cloud));
}

double NearDelaunay::Height(const HullPlane& plane, const double* p) {
  return plane.normal[0] * p[0] + plane.normal[1] * p[1] + plane.normal[2] * p[2] + plane.offset;
}

std::optional<InterpStatus> NearDelaunay::SpectrumAt(std::span<const double> query,
                                                     std::span<double> spectrum,
                                                     std::size_t most_points) const {
  if (query.size() != 3 || spectrum.size() != static_cast<std::size_t>(samples_->bands())) {
    return InterpStatus::kOutsideHull;  // as DelaunayInterpolator::EvaluateSpectrum
  }
  double x[3];
  for (std::size_t i = 0; i < 3; ++i) x[i] = query[i] * cloud_.scale[i];
  for (std::size_t i = 0; i < 3; ++i) {
    // The locator's bounds test (SimplexLocator::InBounds), NaN included.
    if (!(x[i] >= lower_[i] && x[i] <= upper_[i])) return InterpStatus::kOutsideHull;
  }
  if (OutsideAll(x)) return InterpStatus::kOutsideHull;
  const std::size_t count = cloud_.size();
  for (std::size_t k = kFirstPoints;; k *= kGrowth) {
    const std::size_t take = std::min({k, most_points, count});
    if (std::optional<InterpStatus> answer = FromNearest(x, take, spectrum)) return answer;
    if (take == count || take == most_points) return std::nullopt;
  }
}

Status NearDelaunay::MakeHull() const {
  Result<std::vector<std::array<double, 4>>> planes = ConvexHullPlanes3(cloud_.scaled);
  if (!planes.ok()) return planes.status();
  hull_->planes.reserve(planes->size());
  for (const std::array<double, 4>& plane : *planes) {
    hull_->planes.push_back({{plane[0], plane[1], plane[2]}, plane[3]});
  }
  return Status::Ok();
}

bool NearDelaunay::OutsideAll(const double* x) const {
  std::call_once(hull_->once, [this] { hull_->made = MakeHull().ok(); });
  if (!hull_->made) return false;
  const HullPlane* farthest = nullptr;
  double height = kBeyond * diagonal_;
  for (const HullPlane& plane : hull_->planes) {
    if (const double h = Height(plane, x); h > height) {
      height = h;
      farthest = &plane;
    }
  }
  if (farthest == nullptr) return false;
  // Rounding in the plane (or a hull face that is not one) must not decide it: every point on
  // the plane's inner side.
  for (std::size_t p = 0; p < cloud_.size(); ++p) {
    if (Height(*farthest, cloud_.scaled_point(p).data()) > kOnPlane * diagonal_) return false;
  }
  return true;
}

std::optional<InterpStatus> NearDelaunay::FromNearest(const double* x, std::size_t k,
                                                      std::span<double> spectrum) const {
  const std::size_t count = cloud_.size();
  if (k < 4) return std::nullopt;
  // The k nearest points, and every point as near as the k-th (ties all in or all out).
  std::vector<std::pair<double, std::uint32_t>> by_distance(count);
  for (std::size_t p = 0; p < count; ++p) {
    by_distance[p] = {SquaredDistance<3>(x, cloud_.scaled_point(p).data()),
                      static_cast<std::uint32_t>(p)};
  }
  std::nth_element(by_distance.begin(), by_distance.begin() + static_cast<std::ptrdiff_t>(k - 1),
                   by_distance.end());
  const double radius2 = by_distance[k - 1].first;
  std::vector<std::uint32_t> near;
  std::vector<bool> in_near(count, false);
  for (const auto& [d2, p] : by_distance) {
    if (d2 <= radius2) near.push_back(p);
  }
  std::sort(near.begin(), near.end());  // rank order, as the whole triangulation has them
  std::vector<double> local;
  local.reserve(near.size() * 3);
  for (const std::uint32_t p : near) {
    in_near[p] = true;
    const auto s = cloud_.scaled_point(p);
    local.insert(local.end(), s.begin(), s.end());
  }

  Result<QhullTriangulation> triangulation = TriangulateWithCgal3(local);
  if (!triangulation.ok()) return std::nullopt;  // e.g. the near points on one plane
  Result<SimplexLocator> locator = SimplexLocator::Build(local, 3, std::move(*triangulation));
  if (!locator.ok()) return std::nullopt;
  const SimplexLocation loc = locator->Locate(std::span<const double>(x, 3));
  if (!loc.inside) return std::nullopt;  // outside these points' hull: not proved here

  const std::span<const std::int32_t> corners = locator->vertices(loc.simplex);
  std::array<std::int32_t, 4> cell{};
  for (std::size_t m = 0; m < 4; ++m) {
    cell[m] = static_cast<std::int32_t>(near[static_cast<std::size_t>(corners[m])]);
  }
  if (k < count && !OutsideCircumsphere(cloud_.scaled, cell, in_near)) return std::nullopt;

  std::array<const double*, 4> spectra{};
  for (std::size_t m = 0; m < 4; ++m) {
    spectra[m] = samples_->spectrum(cloud_.sample[static_cast<std::size_t>(cell[m])]).data();
  }
  BlendSpectra(std::span<const double>(loc.weights.data(), 4),
               std::span<const double* const>(spectra.data(), 4), spectrum);
  return InterpStatus::kOk;
}

}  // namespace brdf::interp
