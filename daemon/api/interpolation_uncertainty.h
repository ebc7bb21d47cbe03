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

// The parts of an answer's uncertainty the API sends. Interpolate sends every part;
// InterpolateBatch leaves out `combined` (clients add measurement and interpolation in quadrature,
// brdf.proto) and, unless asked (include_uncertainty_shared), `shared`: its answers then grow by
// two spectra of floats instead of four of doubles.
struct UncertaintyParts {
  bool shared = true;
  bool combined = true;
};

// Fills out->uncertainty for `answer`, evaluated on `index`, with `parts`; nothing when the
// answer is not OK. The spectra are floats; `combined` is evaluated from the two rounded parts
// (sqrt(m² + i²) in double, rounded to float), as a client computes it from a batch's answer.
void AddInterpolationUncertainty(const interp::Interpolation& answer, const IndexSnapshot& index,
                                 UncertaintyParts parts, v1::InterpolationResult* out);

}  // namespace brdf::daemon
