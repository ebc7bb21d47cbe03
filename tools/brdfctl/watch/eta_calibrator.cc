#include "tools/brdfctl/watch/eta_calibrator.h"

#include <algorithm>

namespace brdf::ctl {

void EtaCalibrator::OnStep(v1::StepKind kind, double daemon_eta_s, double now_s) {
  if (kind != v1::STEP_KIND_PROMPT && last_time_s_ && last_eta_s_) {
    const double model = *last_eta_s_ - daemon_eta_s;
    const double real = now_s - *last_time_s_;
    if (model > 0 && real >= 0) {
      model_s_ += model;
      real_s_ += real;
      ++steps_;
    }
  }
  last_time_s_ = now_s;
  last_eta_s_ = daemon_eta_s;
}

std::optional<double> EtaCalibrator::factor() const {
  if (steps_ < kMinSteps || real_s_ < kMinRealSeconds || model_s_ <= 0) return std::nullopt;
  return std::clamp(real_s_ / model_s_, 0.001, 1000.0);
}

double EtaCalibrator::Eta(double daemon_eta_s) const {
  const std::optional<double> f = factor();
  return f ? daemon_eta_s * *f : daemon_eta_s;
}

}  // namespace brdf::ctl
