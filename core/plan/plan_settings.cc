#include "core/plan/plan_settings.h"

#include <algorithm>
#include <cmath>

namespace brdf::plan {

PlanSettings ResolveSettings(const v1::Plan& plan) {
  PlanSettings s;
  const v1::ReferencePolicy& ref = plan.reference();
  if (ref.has_per_detector_position())
    s.reference.per_detector_position = ref.per_detector_position();
  s.reference.every_n_readings = ref.every_n_readings();
  s.reference.every_minutes = ref.every_minutes();
  s.reference.alpha_deg = ref.pose().alpha();
  if (ref.pose().has_beta()) s.reference.beta_deg = ref.pose().beta();
  s.reference.dark_with_each_reference = plan.dark().with_each_reference();

  const v1::MeasurementSettings& m = plan.measurement();
  s.measurement.integration_ms = m.integration_ms();
  if (m.averages() != 0) s.measurement.averages = m.averages();

  const v1::RetryPolicy& r = plan.retry();
  if (r.max_attempts() != 0) s.retry.max_attempts = r.max_attempts();
  if (r.has_backoff_ms()) s.retry.backoff_ms = r.backoff_ms();
  if (r.has_backoff_multiplier()) s.retry.backoff_multiplier = r.backoff_multiplier();
  if (r.max_backoff_ms() != 0) s.retry.max_backoff_ms = r.max_backoff_ms();
  return s;
}

GridSpec ResolveGridSpec(const v1::SampleRotation& rotation) {
  GridSpec spec;
  const v1::AngleRange& d = rotation.delta();
  if (d.has_start()) spec.delta_start_deg = d.start();
  if (d.has_stop()) spec.delta_stop_deg = d.stop();
  if (d.has_step()) spec.delta_step_deg = d.step();
  const v1::AngleRange& a = rotation.alpha();
  if (a.has_start()) spec.alpha_start_deg = a.start();
  if (a.has_stop()) spec.alpha_stop_deg = a.stop();
  if (a.has_step()) spec.alpha_step_deg = a.step();
  if (rotation.beta().has_step()) spec.beta_step_deg = rotation.beta().step();
  if (rotation.beta().has_theta_max_deg()) spec.theta_max_deg = rotation.beta().theta_max_deg();
  if (rotation.gamma_size() > 0) {
    spec.gamma_deg.assign(rotation.gamma().begin(), rotation.gamma().end());
  }
  return spec;
}

Pose ReferencePose(const ReferenceSettings& reference, double gamma_deg, double delta_deg) {
  double beta = 0;
  if (reference.beta_deg.has_value()) {
    beta = *reference.beta_deg;
  } else if (delta_deg > kAutoReferenceMaxThetaODeg) {
    beta = delta_deg - kAutoReferenceMaxThetaODeg;
  }
  return Pose{reference.alpha_deg, beta, gamma_deg, delta_deg};
}

std::uint32_t BackoffBeforeAttemptMs(const RetrySettings& retry, std::uint32_t next_attempt) {
  if (next_attempt <= 1) return 0;
  double wait = retry.backoff_ms;
  for (std::uint32_t i = 2; i < next_attempt && wait < retry.max_backoff_ms; ++i) {
    wait *= retry.backoff_multiplier;
  }
  wait = std::min(wait, static_cast<double>(retry.max_backoff_ms));
  return static_cast<std::uint32_t>(std::lround(std::max(wait, 0.0)));
}

Directions TargetDirections(const v1::DirectionTarget& target) {
  if (target.has_phi_i() || target.has_phi_o()) {
    return Directions{target.theta_i(), target.phi_i(), target.theta_o(), target.phi_o()};
  }
  return Directions{target.theta_i(), 0, target.theta_o(), target.phi()};
}

bool SampleFixedMethod(const v1::Plan& plan) {
  return plan.has_sample_fixed() || (plan.has_adaptive() && plan.adaptive().has_sample_fixed());
}

}  // namespace brdf::plan
