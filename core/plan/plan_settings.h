// The defaults of a plan, in one place. A brdf.v1.Plan leaves fields unset (proto3 zeros or
// unset `optional`s, see proto/brdf/v1/plan.proto); these functions turn it into concrete
// values. Everything that reads a plan (expansion, validation, timing, the executor's retry and
// meter settings) goes through them, so a default is defined exactly once.
#pragma once

#include <cstdint>
#include <optional>

#include "brdf/v1/plan.pb.h"
#include "core/geometry.h"
#include "core/pose.h"

namespace brdf::plan {

// Hard caps on what one plan may ask for.
inline constexpr int kMaxSteps = 200000;  // steps of an expanded plan (ValidatePlan refuses more)

// Defaults of the auto reference pose (ReferencePose.beta unset): β = 0 (lamp at normal
// incidence, geometry.md's default) while the detector then sees the white at θo = δ ≤ this
// angle; beyond it β = δ − this angle, so the detector stays at this angle from the normal
// instead of looking at the white from behind (the paper's δ reaches 146.25°).
inline constexpr double kAutoReferenceMaxThetaODeg = 75;
// A reference pose must keep lamp and detector within this angle of the white's normal: nearer
// grazing, the Lambertian assumption and cos θi,ref are too uncertain to divide by.
inline constexpr double kReferenceThetaMaxDeg = 85;

struct ReferenceSettings {
  bool per_detector_position = true;
  std::uint32_t every_n_readings = 0;  // 0: off
  double every_minutes = 0;            // 0: off
  double alpha_deg = 0;                // model angle
  std::optional<double> beta_deg;      // model angle; unset: auto (ReferenceBetaDeg)
  bool dark_with_each_reference = false;
};

struct MeasurementChoice {
  std::uint32_t integration_ms = 0;  // 0: adaptive
  std::uint32_t averages = 1;
  bool adaptive() const { return integration_ms == 0; }
};

struct RetrySettings {
  std::uint32_t max_attempts = 3;
  std::uint32_t backoff_ms = 1000;
  double backoff_multiplier = 2;
  std::uint32_t max_backoff_ms = 30000;
};

struct PlanSettings {
  ReferenceSettings reference;
  MeasurementChoice measurement;
  RetrySettings retry;
};

// The plan's policies with every unset field replaced by its default. Does not validate (see
// ValidatePlan): out-of-range values are passed through as given.
PlanSettings ResolveSettings(const v1::Plan& plan);

// The sample-rotation loops with defaults filled in (GridSpec{}'s defaults: the paper's grid).
GridSpec ResolveGridSpec(const v1::SampleRotation& rotation);

// The reference pose (model angles) at detector position delta_deg, with γ = gamma_deg.
Pose ReferencePose(const ReferenceSettings& reference, double gamma_deg, double delta_deg);

// How long to wait before attempt `next_attempt` (2 = the first retry), ms: backoff_ms ·
// multiplier^(next_attempt − 2), capped at max_backoff_ms. 0 for next_attempt ≤ 1.
std::uint32_t BackoffBeforeAttemptMs(const RetrySettings& retry, std::uint32_t next_attempt);

// True when lamp and detector are placed by hand at each target and the holder stays still: a
// sample-fixed plan, or an adaptive plan in the sample-fixed method's form (Adaptive.sample_fixed).
bool SampleFixedMethod(const v1::Plan& plan);

// A sample-fixed target as four angles: the isotropic form becomes (θi, 0, θo, φ); unset
// fields count as 0 (ValidatePlan reports them as missing).
Directions TargetDirections(const v1::DirectionTarget& target);

}  // namespace brdf::plan
