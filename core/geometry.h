// Rig kinematics: holder and detector pose ↔ incident/outgoing directions in the sample's frame,
// exactly as fixed by docs/geometry.md (read it first), plus the paper's
// sample-rotation sampling loops. Pure; degrees in every interface.
//
// Two kinds of angles meet here. A Pose holds the stage readings (what the rotation stages are
// commanded to and report). The model angles are the α, β, γ, δ of geometry.md, where
// R(α, β, γ) = Rz(β)·Ry(−α)·Rx(γ) turns the sample frame and V(δ) = (cos δ, sin δ, 0) is the
// detector. A HolderConvention maps one to the other; its default is the identity, so for the
// project's default rig a Pose *is* the model angles.
#pragma once

#include <span>
#include <string>
#include <vector>

#include "core/pose.h"
#include "core/status.h"

namespace brdf {

// How one stage's reading relates to the model angle: model = sign · (reading − zero_deg).
// zero_deg is the reading at which the model angle is 0 (the stage's mechanical zero offset);
// sign is −1 when the stage turns the other way round than geometry.md's axis.
struct AxisConvention {
  double sign = +1;  // +1 or −1
  double zero_deg = 0;
  friend bool operator==(const AxisConvention&, const AxisConvention&) = default;
};

// A holder/detector whose axes differ from geometry.md's default. Default: identity on every axis.
// The order of the holder rotations is fixed (Rz(β)·Ry(−α)·Rx(γ)); a rig with another order is
// not representable here.
struct HolderConvention {
  AxisConvention alpha;
  AxisConvention beta;
  AxisConvention gamma;
  AxisConvention delta;
  friend bool operator==(const HolderConvention&, const HolderConvention&) = default;
};

// Checks that every sign is ±1 and every zero offset finite; the message names the axis.
Status ValidateConvention(const HolderConvention& convention);

// Checks that every angle of the pose is finite; the message names the angle.
Status ValidatePose(const Pose& pose);

// Stage readings → model angles, and back. ToReadings does not wrap angles.
Pose ToModelAngles(const Pose& readings, const HolderConvention& convention = {});
Pose ToReadings(const Pose& model, const HolderConvention& convention = {});

// Forward kinematics: the lamp (θi, φi) and detector (θo, φo) directions in the sample frame for a
// pose (stage readings). θ in [0, 180] (above 90: that side is below the surface, see IsValid),
// φ in (−180, 180]. θ is computed with atan2 so that it stays accurate near the normal. A pose with
// non-finite angles gives NaN directions: check it with ValidatePose first.
Directions PoseToDirections(const Pose& pose, const HolderConvention& convention = {});

// Below this polar angle (degrees) a direction is taken as the normal itself and its azimuth as
// undefined, so ToIsotropic sets φ = 0 (geometry.md: "where θi = 0 or θo = 0 ... use φ = 0").
inline constexpr double kNormalThetaEpsilonDeg = 1e-9;

// The isotropic reduction: φ = |φo − φi| folded into [0, 180] (180 = specular side), φ = 0 where
// θi or θo is (within kNormalThetaEpsilonDeg of) 0.
IsoDirection ToIsotropic(const Directions& d);

// A representative of an isotropic point in four angles: (θi, 0, θo, φ).
Directions CanonicalDirections(const IsoDirection& iso);

// True when both directions are finite and at most theta_max_deg from the normal (lamp and
// detector above the surface by the margin the caller wants).
bool IsValid(const Directions& d, double theta_max_deg);

// Checks an isotropic point: finite, θi and θo in [0, 90], φ in [0, 180]; the message names the
// field.
Status ValidateIsoDirection(const IsoDirection& iso);

// Mechanical ranges of the rig in model angles, for inverse kinematics. Defaults: everything
// geometry.md's rig can do (α in [0, 90], δ in [0, 180]).
struct PoseLimits {
  double alpha_min_deg = 0;
  double alpha_max_deg = 90;
  double delta_min_deg = 0;
  double delta_max_deg = 180;
};

// Inverse kinematics with γ = 0: the pose (stage readings) that puts the lamp and detector at the
// isotropic point `target`. Follows geometry.md's closed form (with δ and c·sin β computed from
// cross products, which stays accurate for small δ). β is returned in (−180, 180] before the
// convention is applied. Where δ = 0 (θi = θo, φ = 0) any normal at θi from the lamp works; we
// pick α = 0, β = θi (a pure turn of the vertical axis). Where δ = 180° (both grazing, opposite)
// we pick α = 0, β = 90°.
// Errors (kInvalidArgument, naming the field or angle): a non-finite or out-of-range target, an
// invalid convention, no real α (cos α > 1), α or δ outside `limits`.
Result<Pose> InverseKinematics(const IsoDirection& target, const HolderConvention& convention = {},
                               const PoseLimits& limits = {});

// The paper's sample-rotation loops, in model angles. Defaults reproduce the paper:
// δ = 0, 11.25, …, 146.25 (14 positions: "0 to 150 every 11.25", 150 itself is not on the grid),
// α = 0, 10, …, 70 (8), β every 5° over (−180, 180] where both θi and θo ≤ theta_max_deg,
// γ = 0. This gives 2,320 poses and 2,153 distinct (θi, θo, φ) points.
struct GridSpec {
  // Values start, start + step, … up to stop inclusive (within 1e-9°).
  double delta_start_deg = 0;
  double delta_stop_deg = 150;
  double delta_step_deg = 11.25;
  double alpha_start_deg = 0;
  double alpha_stop_deg = 70;
  double alpha_step_deg = 10;
  // β: every multiple of beta_step_deg in (−180, 180] whose pose keeps both directions valid.
  double beta_step_deg = 5;
  // "Above the surface by a margin": just under 90° so that grazing poses are left out.
  double theta_max_deg = 89.999;
  // Dial positions for anisotropic samples; {0} for isotropic ones.
  std::vector<double> gamma_deg = {0};
};

// Checks the spec (finite values, positive steps, start ≤ stop, 0 < theta_max ≤ 90, at least one
// γ); the message names the field.
Status ValidateGridSpec(const GridSpec& spec);

// Expands the loops into poses (stage readings, via `convention`), in measurement order: γ
// outermost (a manual dial, changed least often), then δ (the detector), then α, then β innermost.
// kInvalidArgument for an invalid spec, and for one whose every pose leaves the lamp or the
// detector at or beyond theta_max (nothing to measure).
Result<std::vector<Pose>> ExpandSampleRotationGrid(const GridSpec& spec,
                                                   const HolderConvention& convention = {});

// The distinct isotropic points of a list, in first-seen order. Two points are the same when all
// three coordinates differ by at most tolerance_deg (the first one seen stands for the group).
std::vector<IsoDirection> DistinctIsoPoints(std::span<const IsoDirection> points,
                                            double tolerance_deg = 1e-9);
std::size_t CountDistinctIsoPoints(std::span<const IsoDirection> points,
                                   double tolerance_deg = 1e-9);

}  // namespace brdf
