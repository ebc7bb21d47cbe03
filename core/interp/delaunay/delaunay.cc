#include "core/interp/delaunay/delaunay.h"

#include <algorithm>
#include <array>
#include <charconv>
#include <cmath>
#include <numeric>
#include <string>
#include <utility>

#include "core/interp/barycentric.h"
#include "core/interp/delaunay/cgal.h"
#include "core/interp/delaunay/locate.h"
#include "core/interp/delaunay/qhull.h"
#include "core/interp/search/point_cloud.h"

namespace brdf::interp {
namespace {

const char* AxisNames(int dims) {
  return dims == 3 ? "(θi, θo, φ)" : "(θi, φi, θo, φo)";
}

// Each coordinate as printf's "%.6g" writes it (std::to_chars's general form with a precision is
// specified as that), without printf's cost: a grid export asks for thousands of these.
std::string FormatPoint(std::span<const double> x) {
  std::string out = "(";
  char buffer[32];
  for (std::size_t i = 0; i < x.size(); ++i) {
    if (i > 0) out += ", ";
    const auto written =
        std::to_chars(buffer, buffer + sizeof buffer, x[i], std::chars_format::general, 6);
    out.append(buffer, written.ptr);
  }
  return out + ")";
}

}  // namespace

struct DelaunayInterpolator::Impl {
  std::shared_ptr<const SampleSet> samples;
  int dims = 0;
  std::array<double, 4> scale{1, 1, 1, 1};
  // Per triangulated point: the SampleSet index it comes from and its (unscaled) coordinates,
  // together so that an answer's vertex costs one cache miss, not two.
  struct Point {
    std::size_t sample = 0;
    std::array<double, 4> coords{};
  };
  std::vector<Point> points;
  SimplexLocator locator;

  Interpolation Answer(std::span<const double> query, std::int32_t hint, std::int32_t* found) const;
};

Interpolation DelaunayInterpolator::Impl::Answer(std::span<const double> query, std::int32_t hint,
                                                 std::int32_t* found) const {
  Interpolation out;
  out.method = Method::kDelaunay;
  if (query.size() != static_cast<std::size_t>(dims)) {
    out.status = InterpStatus::kOutsideHull;
    out.detail = "query has " + std::to_string(query.size()) + " coordinates; expected " +
                 std::to_string(dims) + " " + AxisNames(dims);
    return out;
  }
  std::array<double, 4> x{};
  for (int i = 0; i < dims; ++i) x[i] = query[i] * scale[i];
  const SimplexLocation loc =
      locator.LocateFrom(std::span<const double>(x.data(), query.size()), hint);
  if (!loc.inside) {
    out.status = InterpStatus::kOutsideHull;
    out.detail = FormatPoint(query) + " is outside the convex hull of the " +
                 std::to_string(points.size()) + " triangulated points";
    return out;
  }
  *found = loc.simplex;

  const std::size_t bands = static_cast<std::size_t>(samples->bands());
  const std::span<const std::int32_t> corners = locator.vertices(loc.simplex);
  // The vertex spectra are scattered over the sample set: start fetching all of them now, so
  // that the misses overlap each other and the allocations below instead of queueing.
  std::array<const Point*, kMaxSimplexVertices> vertex{};
  std::array<const double*, kMaxSimplexVertices> spectra{};
  for (std::size_t m = 0; m < corners.size(); ++m) {
    vertex[m] = &points[static_cast<std::size_t>(corners[m])];
    spectra[m] = samples->spectrum(vertex[m]->sample).data();
    for (std::size_t b = 0; b < bands; b += 8) __builtin_prefetch(spectra[m] + b);
  }
  out.status = InterpStatus::kOk;
  out.spectrum.resize(bands);
  out.vertices.resize(corners.size());
  for (std::size_t m = 0; m < corners.size(); ++m) {
    Vertex& v = out.vertices[m];
    v.id = samples->id(vertex[m]->sample);
    v.index = vertex[m]->sample;
    v.coords.assign(vertex[m]->coords.begin(), vertex[m]->coords.begin() + dims);
    v.weight = loc.weights[m];
  }
  // The shared blend: same vertices and weights, bit-identical spectrum whichever method.
  BlendSpectra(std::span<const double>(loc.weights.data(), corners.size()),
               std::span<const double* const>(spectra.data(), corners.size()), out.spectrum);
  out.detail = "simplex " + std::to_string(loc.simplex);
  return out;
}

Result<DistinctCloud> DistinctDelaunayPoints(const SampleSet& samples, const Options& options) {
  // Measured samples, then symmetry copies, scaled: the same cloud every method searches.
  BRDF_ASSIGN_OR_RETURN(PointCloud cloud, BuildPointCloud(samples, options));
  const std::size_t count = cloud.size();
  DistinctCloud out;
  out.dims = cloud.dims;
  std::copy(cloud.scale.begin(), cloud.scale.end(), out.scale.begin());

  // Coincident points (after scaling) would make Qhull drop one of them arbitrarily: keep the
  // lowest rank (stable sort, so each run of equal points starts with it).
  std::vector<std::size_t> order(count);
  std::iota(order.begin(), order.end(), std::size_t{0});
  const auto less = [&](std::size_t a, std::size_t b) {
    const auto pa = cloud.scaled_point(a);
    const auto pb = cloud.scaled_point(b);
    return std::lexicographical_compare(pa.begin(), pa.end(), pb.begin(), pb.end());
  };
  std::stable_sort(order.begin(), order.end(), less);
  std::vector<bool> keep(count, true);
  for (std::size_t i = 1; i < count; ++i) {
    if (!less(order[i - 1], order[i])) keep[order[i]] = false;
  }
  for (std::size_t p = 0; p < count; ++p) {
    if (!keep[p]) continue;
    out.sample.push_back(cloud.sample[p]);
    const auto raw = cloud.point(p);
    out.coords.insert(out.coords.end(), raw.begin(), raw.end());
    const auto scaled = cloud.scaled_point(p);
    out.scaled.insert(out.scaled.end(), scaled.begin(), scaled.end());
  }
  return out;
}

Result<std::unique_ptr<DelaunayInterpolator>> DelaunayInterpolator::Create(
    std::shared_ptr<const SampleSet> samples, const Options& options) {
  if (samples == nullptr) return InvalidArgument("Delaunay interpolation: no sample set given");
  Result<DistinctCloud> built = DistinctDelaunayPoints(*samples, options);
  if (!built.ok()) return built.status().WithContext("Delaunay interpolation");
  DistinctCloud& cloud = built.value();
  const int dims = cloud.dims;
  const std::array<double, 4> scale = cloud.scale;
  std::vector<Impl::Point> points(cloud.size());
  for (std::size_t p = 0; p < points.size(); ++p) {
    points[p].sample = cloud.sample[p];
    const auto raw = cloud.point(p);
    std::copy(raw.begin(), raw.end(), points[p].coords.begin());
  }
  const std::vector<double>& distinct = cloud.scaled;

  // 3-D (isotropic) by CGAL, far faster on a rig's cospherical poses; 4-D by Qhull.
  BRDF_ASSIGN_OR_RETURN(
      QhullTriangulation triangulation,
      dims == 3 ? TriangulateWithCgal3(distinct) : TriangulateWithQhull(distinct, dims));
  BRDF_ASSIGN_OR_RETURN(SimplexLocator locator,
                        SimplexLocator::Build(distinct, dims, std::move(triangulation)));
  auto impl = std::make_unique<const Impl>(
      Impl{std::move(samples), dims, scale, std::move(points), std::move(locator)});
  return std::unique_ptr<DelaunayInterpolator>(new DelaunayInterpolator(std::move(impl)));
}

DelaunayInterpolator::DelaunayInterpolator(std::unique_ptr<const Impl> impl)
    : impl_(std::move(impl)) {}
DelaunayInterpolator::~DelaunayInterpolator() = default;

int DelaunayInterpolator::dims() const {
  return impl_->dims;
}

std::size_t DelaunayInterpolator::HeapBytes() const {
  return sizeof(Impl) + impl_->points.capacity() * sizeof(Impl::Point) + impl_->locator.HeapBytes();
}

Interpolation DelaunayInterpolator::Evaluate(std::span<const double> query) const {
  std::int32_t found = -1;
  return impl_->Answer(query, -1, &found);
}

Interpolation DelaunayInterpolator::EvaluateFrom(std::span<const double> query,
                                                 LocateHint& hint) const {
  return impl_->Answer(query, hint.simplex, &hint.simplex);
}

Status DelaunayInterpolator::EvaluateBatch(std::span<const double> queries,
                                           std::vector<Interpolation>& out) const {
  const auto d = static_cast<std::size_t>(impl_->dims);
  if (queries.size() % d != 0) {
    return InvalidArgument("Delaunay batch: " + std::to_string(queries.size()) +
                           " coordinates is not a whole number of " + std::to_string(d) +
                           "-D queries");
  }
  const std::size_t n = queries.size() / d;
  out.clear();
  out.reserve(n);
  LocateHint hint;
  for (std::size_t q = 0; q < n; ++q) out.push_back(EvaluateFrom(queries.subspan(q * d, d), hint));
  return Status::Ok();
}

InterpStatus DelaunayInterpolator::EvaluateSpectrum(std::span<const double> query,
                                                    std::span<double> spectrum,
                                                    LocateHint& hint) const {
  const Impl& im = *impl_;
  const auto bands = static_cast<std::size_t>(im.samples->bands());
  if (query.size() != static_cast<std::size_t>(im.dims) || spectrum.size() != bands) {
    return InterpStatus::kOutsideHull;
  }
  std::array<double, 4> x{};
  for (int i = 0; i < im.dims; ++i) x[i] = query[i] * im.scale[i];
  const SimplexLocation loc =
      im.locator.LocateFrom(std::span<const double>(x.data(), query.size()), hint.simplex);
  if (!loc.inside) return InterpStatus::kOutsideHull;
  hint.simplex = loc.simplex;
  const std::span<const std::int32_t> corners = im.locator.vertices(loc.simplex);
  std::array<const double*, kMaxSimplexVertices> spectra{};
  for (std::size_t m = 0; m < corners.size(); ++m) {
    spectra[m] =
        im.samples->spectrum(im.points[static_cast<std::size_t>(corners[m])].sample).data();
  }
  BlendSpectra(std::span<const double>(loc.weights.data(), corners.size()),
               std::span<const double* const>(spectra.data(), corners.size()), spectrum);
  return InterpStatus::kOk;
}

std::size_t DelaunayInterpolator::point_count() const {
  return impl_->points.size();
}
std::size_t DelaunayInterpolator::simplex_count() const {
  return impl_->locator.simplex_count();
}
std::size_t DelaunayInterpolator::flat_simplex_count() const {
  return impl_->locator.degenerate_count();
}

Result<std::unique_ptr<Interpolator>> MakeDelaunayInterpolator(
    std::shared_ptr<const SampleSet> samples, const Options& options) {
  BRDF_ASSIGN_OR_RETURN(std::unique_ptr<DelaunayInterpolator> made,
                        DelaunayInterpolator::Create(std::move(samples), options));
  return std::unique_ptr<Interpolator>(std::move(made));
}

}  // namespace brdf::interp
