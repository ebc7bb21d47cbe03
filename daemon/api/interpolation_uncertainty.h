// The uncertainty of one interpolated spectrum as the API gives it (InterpolationResult.
// uncertainty; docs/uncertainty.md, "Interpolated values"): the measurement part blended from
// the vertices' reading budgets by core/uncertainty/blend.h (shared terms correlated), the
// interpolation term from the vertices' spread about the blend, and their quadrature sum.
// What cannot be estimated is named in not_estimated: a vertex without a budget, a quantity other
// than the BRDF (the stored budgets are of the BRDF), the interpolation term of the nearest
// method (one vertex).
#pragma once

#include "brdf/v1/brdf.pb.h"
#include "core/interp/interpolator.h"
#include "daemon/index/cache.h"

namespace brdf::daemon {

// Fills out->uncertainty for `answer`, evaluated on `index`; nothing when the answer is not OK.
void AddInterpolationUncertainty(const interp::Interpolation& answer, const IndexSnapshot& index,
                                 v1::InterpolationResult* out);

}  // namespace brdf::daemon
