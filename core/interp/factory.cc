// MakeInterpolator: the one entry point that picks a method. Kept in its own file so that code
// which only needs the octant or nearest methods (their own factories) does not pull in Qhull.
#include "core/interp/delaunay/delaunay.h"
#include "core/interp/half_difference.h"
#include "core/interp/interpolator.h"
#include "core/interp/nearest.h"
#include "core/interp/octant/octant.h"
#include "core/interp/trend.h"

namespace brdf::interp {

Result<std::unique_ptr<Interpolator>> MakeInterpolator(Method method,
                                                       std::shared_ptr<const SampleSet> samples,
                                                       const Options& options) {
  if (options.trend == Trend::kBivariate) {
    return MakeTrendInterpolator(method, std::move(samples), options);
  }
  if (options.coordinates == Coordinates::kHalfDifference) {
    return MakeHalfDifferenceInterpolator(method, std::move(samples), options);
  }
  switch (method) {
    case Method::kOctant:
      return MakeOctantInterpolator(std::move(samples), options);
    case Method::kDelaunay:
      return MakeDelaunayInterpolator(std::move(samples), options);
    case Method::kNearest:
      return MakeNearestInterpolator(std::move(samples), options);
  }
  return InvalidArgument("MakeInterpolator: unknown method " +
                         std::to_string(static_cast<int>(method)));
}

}  // namespace brdf::interp
