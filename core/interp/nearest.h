// Nearest-neighbour "interpolation": the spectrum of the sample nearest to the query (scaled space
// of Options.axis_scale, samples plus symmetry copies; ties to the lower rank, i.e. the earlier
// sample), with weight 1. The baseline the blending methods are compared against. Always kOk for a
// valid query (detail empty); a query with the wrong number of coordinates or a non-finite one is
// answered kOutsideHull with a detail that says so. Pure: no I/O.
#pragma once

#include <memory>

#include "core/interp/interpolator.h"
#include "core/status.h"

namespace brdf::interp {

// Errors (kInvalidArgument): null or empty samples, not 3D/4D, bad options (ValidateOptions).
Result<std::unique_ptr<Interpolator>> MakeNearestInterpolator(
    std::shared_ptr<const SampleSet> samples, const Options& options = {});

}  // namespace brdf::interp
