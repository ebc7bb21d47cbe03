#include "tools/brdf-sim/optics/errors.h"

#include <cmath>

namespace brdf::sim {
namespace {

// Streams of the run's seed, one per error source (the detector's noise uses the seed itself).
enum class Stream : std::uint32_t { kSession = 1, kLamp = 2, kPose = 3, kGain = 4 };

std::mt19937_64 Engine(std::uint64_t seed, Stream stream) {
  std::seed_seq seq{static_cast<std::uint32_t>(seed), static_cast<std::uint32_t>(seed >> 32),
                    0x6272u, static_cast<std::uint32_t>(stream)};
  return std::mt19937_64(seq);
}

double Normal(std::mt19937_64& rng) {
  return std::normal_distribution<double>(0.0, 1.0)(rng);
}

constexpr double kSecondsPerHour = 3600;

}  // namespace

RigErrors::RigErrors(const ErrorSources& sources, std::uint64_t seed)
    : sources_(sources),
      lamp_rng_(Engine(seed, Stream::kLamp)),
      pose_rng_(Engine(seed, Stream::kPose)),
      gain_rng_(Engine(seed, Stream::kGain)) {
  // Drawn once, in a fixed order, whether or not each source is on.
  std::mt19937_64 session = Engine(seed, Stream::kSession);
  const double white_z = Normal(session);
  const double shift_z = Normal(session);
  white_factor_ = 1.0 + sources_.white_error * white_z;
  wavelength_shift_nm_ =
      sources_.wavelength_shift_nm + sources_.wavelength_shift_sigma_nm * shift_z;
}

double RigErrors::LampFactor() const {
  std::lock_guard lock(mu_);
  return 1.0 + sources_.lamp_drift_per_hour * lamp_hours_ + lamp_wander_;
}

void RigErrors::AdvanceLamp(double seconds) {
  if (!(seconds > 0)) return;
  std::lock_guard lock(mu_);
  const double hours = seconds / kSecondsPerHour;
  lamp_hours_ += hours;
  if (sources_.lamp_wander_per_sqrt_hour > 0) {
    lamp_wander_ += sources_.lamp_wander_per_sqrt_hour * std::sqrt(hours) * Normal(lamp_rng_);
  }
}

Pose RigErrors::TruePose(const Pose& reported) {
  if (sources_.pose_jitter_deg <= 0) return reported;
  std::lock_guard lock(mu_);
  const double s = sources_.pose_jitter_deg;
  Pose p = reported;
  p.alpha += s * Normal(pose_rng_);
  p.beta += s * Normal(pose_rng_);
  p.gamma += s * Normal(pose_rng_);
  p.delta += s * Normal(pose_rng_);
  return p;
}

double RigErrors::NextGain() {
  if (sources_.gain_noise <= 0) return 1.0;
  std::lock_guard lock(mu_);
  return 1.0 + sources_.gain_noise * Normal(gain_rng_);
}

}  // namespace brdf::sim
