// The uncertainty model an adaptive session chooses its poses by (uncertainty_model.h): the
// uncertainty of the interpolated BRDF as docs/uncertainty.md defines it ("Interpolated values"),
// predicted over the plan's region from the readings so far, and how much one more reading would
// lower it (docs/adaptive.md, "The uncertainty model").
//
// The scalar it judges is each reading's `brdf` (the engine's mean over 400–700 nm), interpolated
// by the plan's judged method (octant or Delaunay, core/interp) over the readings' isotropic
// directions (θi, θo, φ) with the options of JudgeOptions(). Isotropic only: an anisotropic plan
// (several dial positions γ) is judged in its isotropic reduction, which does not see how the
// BRDF changes with γ.
//
// Map(readings):
//   - The evaluation directions: a fixed lattice over the region, θi and θo every 5° (cell
//     centres within the region's limits; one at the middle of a range narrower than 5°) and φ
//     every 10° (5° … 175°), each weighted by its share of the projected solid angle of the
//     direction pairs, sin θi · sin θo (the cos θi · cos θo is in the quantity, below).
//   - At each one, the interpolant's answer y = Σ wᵢ fᵢ and its relative uncertainty:
//       measurement    u_m² = Σ (wᵢ · uᵢ · fᵢ)²: the vertices' relative u (ReadingSoFar's) blended
//                      as independent (the shared terms a session's readings have in common are
//                      not known here; more readings would not reduce them anyway);
//       interpolation  u_int = c · s: s the vertices' weighted spread about y
//                      (uncertainty/blend.h, InterpolationSpread), c the scale fitted from the
//                      readings themselves: readings held out in folds (a fixed hash of their
//                      positions), predicted from the rest by the same method, their residuals
//                      against c · s with their noise (interpolation_calibration.h, k = 2,
//                      95 %). With fewer than 8 held-out readings predicted, c = 1 (the spread
//                      as it is, which is wider than the error: docs/uncertainty.md).
//     A direction the method cannot answer (an empty octant, outside the hull) counts as
//     unknown: kUnknownRelative times the region's RMS BRDF (over the answered directions).
//   - Remaining() = k · sqrt(Σₑ mₑ (cₑ uₑ)² / Σₑ mₑ (cₑ yₑ)²), cₑ = cos θi · cos θo and
//     unknown directions at the RMS BRDF: the relative RMS uncertainty of the cosine-weighted
//     BRDF over the region — the figure the adaptive benchmark measures as an error. For
//     target.kind kExpandedUncertainty, uₑ² = u_m² + u_int² and k = 2 (U = 2u, the plan's
//     `expandedUncertainty`); for kExpectedError, uₑ = u_int alone and k = 1.
//
// PredictedGain(candidate): a reading at the candidate's isotropic point p enters the cell of an
// evaluation direction e when it is nearer to e than the nearest reading (or mirror image) in
// p's orthant about e — the octant method's own test — and within kReachDeg of e. In an answered
// cell it takes the place of the simplex's vertex in that orthant (or, when the simplex has none
// there, of its farthest vertex); the cell's size h (its largest vertex distance) becomes h', and
// e's interpolation term falls in proportion, u_int · h' / h (the vertices' spread follows the
// cell's size where the BRDF is smooth). The measurement part stays. An unknown direction with E
// empty orthants loses a share (1 − (d / kReachDeg)²) / E of its unknown term to a reading at
// distance d < kReachDeg that fills one of them. The gain is the fall of Remaining() (≥ 0);
// Assume() applies it. Distances are in the interpolator's degrees (θi, θo, φ).
//
// Deterministic: the same readings in the same order give the same map and the same gains.
// Readings with a non-finite direction or BRDF, or a negative or non-finite u, are left out.
// No usable readings: every direction is unknown, Remaining() = k · kUnknownRelative, and a
// reading anywhere gains near it (within kReachDeg). If the judged method cannot be built
// over the readings (Delaunay over fewer than 4 readings, or all of them in one plane), the
// octant method stands in; if that fails too, every direction is unknown. Pure: no I/O.
//
// Cost (docs/adaptive.md, bench_adaptive_study --timing): on 2,000 readings Map() takes about
// 0.2 s of CPU and a round of 24 picks over 5,000 candidates, its Map() included, about 0.8 s.
#pragma once

#include <memory>

#include "core/adaptive/adaptive_spec.h"
#include "core/adaptive/uncertainty_model.h"
#include "core/interp/interpolator.h"

namespace brdf::adaptive {

// The relative uncertainty given to a direction the method cannot answer.
inline constexpr double kUnknownRelative = 1.0;
// How near a reading must come to an evaluation direction to count for it (degrees, in
// (θi, θo, φ)): a cheap round (interpolated_model.h, "Cost"); a reading farther away than this
// is predicted to gain nothing there, even when it would enter a larger cell.
inline constexpr double kReachDeg = 30;

// The interpolation options the model judges with, and the adaptive benchmark interpolates with:
// the isotropic mirror images of φ (exact for an isotropic sample, interpolation.md), which let
// the octant method answer up to φ = 0° and 180° (the retro-reflection and specular planes).
interp::Options JudgeOptions();

// The model for `spec` (its region, judged method and target kind).
std::unique_ptr<UncertaintyModel> MakeInterpolatedModel(const AdaptiveSpec& spec);

}  // namespace brdf::adaptive
