// A session "measured" on a known analytic BRDF without a rig: a white reference at the default
// reference pose (α = β = 0, so θi,ref = 0), an optional dark reading, and one sample reading per
// pose of the paper's sample-rotation loops, with the radiances a white-referenced measurement of
// that BRDF would give (I = R · (I0 − D) + D, R = f · π / ρw · cos θi / cos θi,ref). Deriving the
// BRDF from it gives the analytic BRDF back, which makes it the ground truth of the export tests
// and the data of `brdf-export --demo`.
#pragma once

#include "core/analytic_brdf.h"
#include "core/export/session_data.h"
#include "core/geometry.h"

namespace brdf::exports {

struct SyntheticSessionOptions {
  GridSpec poses;  // default: the paper's loops (2,320 poses)
  WavelengthGrid grid = WavelengthGrid::Pr650();
  double white_reflectance = kWhiteStandardReflectance;
  bool with_dark = true;
};

// Reading ids: 1 the reference, 2 the dark (when with_dark), then the samples in pose order.
Result<Session> SyntheticSession(const AnalyticBrdf& brdf,
                                 const SyntheticSessionOptions& options = {});

// The lamp's radiance off the white standard that SyntheticSession uses, I0(λ) in
// W·m⁻²·sr⁻¹·nm⁻¹: a smooth, warm, halogen-like curve.
double SyntheticLampRadiance(double wavelength_nm);

}  // namespace brdf::exports
