// Rusinkiewicz's half/difference angles (1998) for isotropic data, and interpolation in them.
//
// The transform. An isotropic point (θi, θo, φ) stands for the directions ωi = (θi, 0) and
// ωo = (θo, φ) (core/geometry.h: CanonicalDirections). The half vector h = (ωi + ωo)/|ωi + ωo| is
// at (θh, φh); the difference vector d = Ry(−θh) · Rz(−φh) · ωi (ωi seen from a frame whose pole
// is h) is at (θd, φd). MERL's tables use the same vectors (core/export/merl/layout.h). Degrees.
//   θh in [0, 90]: 0 is the mirror configuration (ωo is ωi reflected about the normal); a
//     specular lobe varies along θh and slowly along θd, φd.
//   θd in [0, 90]: the angle between ωi and h (0: retro-reflection, ωi = ωo).
//   φd in [0, 180]: folded by |φd|. Turning ωi and ωo about the normal only changes φh, which an
//     isotropic BRDF ignores (dropped); mirroring both about the plane of incidence turns φd into
//     −φd, which (θi, θo, φ = |φo − φi|) already takes as the same point. So the fold is the one
//     the isotropic coordinates make, nothing more: (θi, θo, φ) ↔ (θh, θd, φd) is one-to-one
//     between φ in [0, 180] and φd in [0, 180], except at the poles below.
//   Reciprocity (swapping ωi and ωo) is φd → 180° − φd in these coordinates (d → −d in the plane
//   of h, then the fold); it is NOT folded: as in (θi, θo, φ), it is an option (reciprocity).
//   Poles: at θd = 0 (ωi = ωo) φd is undefined and set to 0; at θh = 0 (h = n) φh is undefined
//   (taken as 0) and an isotropic BRDF does not depend on φd, so FromHalfDifference(θh = 0, θd, any
//   φd) gives the same (θd, θd, 180°) and ToHalfDifference returns φd = 0 there. Both directions
//   grazing and opposite (ωi + ωo = 0) have no half vector: taken as θh = θd = φd = 90°.
// The inverse takes φh = 0: ωi = Ry(θh) · d, ωo = ωi reflected about h, then ToIsotropic. A round
// trip reproduces (θh, θd, φd) away from the poles (within 1e-9°), and (θi, θo, φ) everywhere
// above the surface.
//
// Interpolation (Options.coordinates = kHalfDifference). The method searches and blends a 3D
// point set like any other: every sample at HalfDifferencePoint = (θh·cos φd, θh·sin φd, θd),
// i.e. (θh, φd) as polar coordinates. In the plain box (θh, θd, φd) the specular configurations
// (θh = 0, where φd means nothing) would be a whole face, and a near-specular query at φd = 90°
// would find the exact mirror reading (φd = 0) half the φd range away; as polar coordinates they
// are the axis, next to every near-specular point. The lobe of a glossy sample is then a function
// of the distance from that axis, the slow variables (θd, and φd around the axis) run across it.
// Then images of every sample that stand for the same pair of directions beyond a boundary of the
// domain, so that queries near a boundary have neighbours on both sides:
//   always:       (x, −y, θd): φd → −φd, the mirror fold (φd = 0 and 180° are the line y = 0; at
//                 θh = 0 this is also the half vector's own pole, (−θh, φh + 180°) being h);
//                 (−x, y, −θd): the difference vector's pole (θd → −θd, φd → φd + 180°), which
//                 gives retro-reflection queries (θd near 0) neighbours below them;
//   reciprocity:  (−x, y, θd): φd → 180° − φd (the swapped pair).
// mirror_phi adds nothing more: its images in (θi, θo, φ) are the fold above, always present here.
// Images rank after the measured samples, in that order (measured samples win ties), and keep the
// id and index of the sample they copy. Options.axis_scale multiplies (x, y, θd); its default,
// kHalfDifferenceScale, is 1 (all three are degrees of the same kind: the paper grid's measured
// RMS barely moves between 1,1,1 and 2,2,1; docs/interpolation.md, "Half/difference coordinates").
// Queries are mapped the same way; an answer's vertices report the (θi, θo, φ) of the directions
// they stand for (an image: those of the sample it copies, up to rounding). Pure: no I/O.
#pragma once

#include <array>
#include <memory>

#include "core/interp/interpolator.h"
#include "core/pose.h"
#include "core/status.h"

namespace brdf::interp {

struct HalfDiffAngles {
  double theta_h = 0;  // degrees
  double theta_d = 0;
  double phi_d = 0;
  friend bool operator==(const HalfDiffAngles&, const HalfDiffAngles&) = default;
};

// The default Options.axis_scale in half/difference coordinates: multipliers of the point
// (θh·cos φd, θh·sin φd, θd) (HalfDifferencePoint).
inline constexpr std::array<double, 3> kHalfDifferenceScale = {1.0, 1.0, 1.0};

// (θi, θo, φ) → (θh, θd, φd), as described above. Non-finite input gives NaN.
HalfDiffAngles ToHalfDifference(const IsoDirection& iso);
// (θh, θd, φd) → (θi, θo, φ) (φh = 0), as described above. Accepts any finite angles (images
// with a negative θh, θd or a φd outside [0, 180] give the directions they stand for); a pair
// below the surface gives θ > 90°.
IsoDirection FromHalfDifference(const HalfDiffAngles& hd);

// The point the interpolators search: (θh·cos φd, θh·sin φd, θd), degrees. (θh, φd) as polar
// coordinates: at θh = 0, where an isotropic BRDF does not depend on φd, all φd meet in one point,
// as all of them are one pair of directions. And back (φd in (−180, 180]).
std::array<double, 3> HalfDifferencePoint(const HalfDiffAngles& hd);
HalfDiffAngles FromHalfDifferencePoint(const std::array<double, 3>& point);

// The interpolator of `method` over the half/difference images of `samples` (3D), answering
// (θi, θo, φ) queries. Errors (kInvalidArgument): null or empty samples, 4D samples (naming
// "coordinates": half/difference angles need isotropic data), bad axis_scale (from the method).
Result<std::unique_ptr<Interpolator>> MakeHalfDifferenceInterpolator(
    Method method, std::shared_ptr<const SampleSet> samples, const Options& options);

}  // namespace brdf::interp
