// What the fit tests share: the paper's directions, a long call context and the spectra of the
// synthetic Cook-Torrance surface (kd(λ) a bump at 600 nm, ks(λ) rising).
#pragma once

#include <gtest/gtest.h>

#include <chrono>
#include <cmath>
#include <numbers>
#include <vector>

#include "core/call_context.h"
#include "core/geometry.h"

namespace brdf::fit::testing {

inline CallContext LongContext(CancelToken token = CancelToken()) {
  return CallContext::WithTimeout(std::chrono::hours(1), std::move(token));
}

// The paper's rig grid: 2,153 distinct (θi, θo, φ).
inline std::vector<IsoDirection> PaperDirections() {
  Result<std::vector<Pose>> poses = ExpandSampleRotationGrid(GridSpec{});
  EXPECT_TRUE(poses.ok());
  std::vector<IsoDirection> iso;
  for (const Pose& p : *poses) iso.push_back(ToIsotropic(PoseToDirections(p)));
  return DistinctIsoPoints(iso);
}

inline double KdAt(double nm) {
  const double u = (nm - 600) / 80;
  return 0.2 + 0.5 * std::exp(-u * u);
}
inline double KsAt(double nm) {
  return 0.8 + 0.4 * (nm - 380) / 400;
}

// A broad retro-reflective lobe (peak when the detector looks back along the lamp), which no
// Cook-Torrance lobe has: kr · exp((cos γ − 1) / w), γ the angle between ωi and ωo.
inline double Retro(const IsoDirection& d, double kr) {
  const double r = std::numbers::pi / 180;
  const double cos_g = std::sin(d.theta_i * r) * std::sin(d.theta_o * r) * std::cos(d.phi * r) +
                       std::cos(d.theta_i * r) * std::cos(d.theta_o * r);
  return kr * std::exp((cos_g - 1) / 0.05);
}

}  // namespace brdf::fit::testing
