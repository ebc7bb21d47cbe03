// The octant method exactly as the paper runs it: every query scans all N points (O(N)) for the
// nearest one in each orthant. The definition the fast, indexed implementation (octant/octant.h) is
// tested against, bit for bit; also `brdf-interp --method octant-reference`. Pure: no I/O.
#pragma once

#include <memory>

#include "core/interp/interpolator.h"
#include "core/status.h"

namespace brdf::interp {

// Same contract and errors as MakeOctantInterpolator; method() is Method::kOctant.
Result<std::unique_ptr<Interpolator>> MakeOctantReferenceInterpolator(
    std::shared_ptr<const SampleSet> samples, const Options& options = {});

}  // namespace brdf::interp
