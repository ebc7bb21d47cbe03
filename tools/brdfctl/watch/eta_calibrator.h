// The ETA `watch` shows. The daemon's ETA (StepCompletion.eta_s) comes from its timing model of
// the rig; a rig that runs faster or slower than the model (brdf-sim with --time-scale, a slow
// meter) makes it wrong by a steady factor. The calibrator measures that factor while watching:
// real seconds between step completions over the model seconds those steps took off the ETA,
// leaving out operator prompts (a person's pace is not the rig's). Until enough steps have been
// seen it passes the daemon's ETA through unchanged.
#pragma once

#include <optional>

#include "brdf/v1/brdf.pb.h"

namespace brdf::ctl {

class EtaCalibrator {
 public:
  // Steps and real seconds that must be seen before the factor is used.
  static constexpr int kMinSteps = 5;
  static constexpr double kMinRealSeconds = 2.0;

  // A step completed `now_s` seconds after an arbitrary origin (a steady clock), with the
  // daemon's ETA after it.
  void OnStep(v1::StepKind kind, double daemon_eta_s, double now_s);
  // Forget the last step's time (after a pause or a prompt the next gap is not the rig's pace).
  void Interrupt() { last_time_s_.reset(); }

  // real seconds per model second, once known.
  std::optional<double> factor() const;
  // The daemon's ETA, scaled by factor() when known.
  double Eta(double daemon_eta_s) const;

 private:
  std::optional<double> last_time_s_;
  std::optional<double> last_eta_s_;
  double real_s_ = 0;
  double model_s_ = 0;
  int steps_ = 0;
};

}  // namespace brdf::ctl
