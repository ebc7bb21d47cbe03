#include "core/adaptive/seed_design.h"

#include <algorithm>
#include <cmath>
#include <numbers>

#include "core/geometry.h"

namespace brdf::adaptive {
namespace {

constexpr unsigned kDrawsPerPose = 512;

double Round2(double deg) {
  return std::round(deg * 100) / 100;
}

// The retro-reflection scan: δ = 0, α = 0, β = θ (θi = θo = β) evenly over the θ range both
// limits allow.
std::vector<Pose> RetroScan(const AdaptiveSpec& spec, const plan::RigDescription& rig) {
  std::vector<Pose> poses;
  const double lo = std::max(spec.region.theta_i_min_deg, spec.region.theta_o_min_deg);
  const double hi = std::min(spec.region.theta_i_max_deg, spec.region.theta_o_max_deg);
  const int n = spec.retro_readings;
  if (n <= 0 || hi < lo) return poses;
  for (int i = 0; i < n; ++i) {
    const double theta = n == 1 ? (lo + hi) / 2 : lo + (hi - lo) * i / (n - 1);
    const Pose pose{0, Round2(theta), spec.gamma_deg.front(), 0};
    if (Reachable(pose, spec.region, rig)) poses.push_back(pose);
  }
  return poses;
}

// Up to `wanted` space-filling poses at (γ, δ).
std::vector<Pose> SpaceFilling(const AdaptiveSpec& spec, const plan::RigDescription& rig,
                               double gamma, double delta, int wanted) {
  std::vector<Pose> poses;
  const unsigned draws = kDrawsPerPose * static_cast<unsigned>(std::max(wanted, 1));
  for (unsigned k = 1; k <= draws && static_cast<int>(poses.size()) < wanted; ++k) {
    const double alpha = std::asin(RadicalInverse(k, 2)) * 180 / std::numbers::pi;
    const double beta = -180 + 360 * RadicalInverse(k, 3);
    const Pose pose{Round2(alpha), Round2(beta), gamma, delta};
    if (Reachable(pose, spec.region, rig)) poses.push_back(pose);
  }
  return poses;
}

}  // namespace

void OrderForTravel(std::vector<Pose>& poses) {
  auto band = [](const Pose& p) { return static_cast<int>(std::floor(p.alpha / 10)); };
  std::sort(poses.begin(), poses.end(), [&](const Pose& a, const Pose& b) {
    if (band(a) != band(b)) return band(a) < band(b);
    if (a.beta != b.beta) return band(a) % 2 == 0 ? a.beta < b.beta : a.beta > b.beta;
    return a.alpha < b.alpha;
  });
}

double RadicalInverse(unsigned index, unsigned base) {
  double result = 0;
  double scale = 1.0 / base;
  for (; index > 0; index /= base, scale /= base) result += (index % base) * scale;
  return result;
}

bool Reachable(const Pose& model, const Region& region, const plan::RigDescription& rig) {
  const Pose readings = ToReadings(model, rig.convention);
  if (!rig.alpha.Contains(readings.alpha) || !rig.beta.Contains(readings.beta) ||
      !rig.delta.Contains(readings.delta)) {
    return false;
  }
  if (rig.has_gamma_axis && !rig.gamma.Contains(readings.gamma)) return false;
  const Directions d = PoseToDirections(model);
  return IsValid(d, 90) && RegionContains(region, d);
}

std::vector<SeedGroup> MakeSeedDesign(const AdaptiveSpec& spec, const plan::RigDescription& rig) {
  std::vector<SeedGroup> groups;
  for (std::size_t g = 0; g < spec.gamma_deg.size(); ++g) {
    const std::size_t every = static_cast<std::size_t>(std::max(spec.seed_delta_every, 1));
    for (std::size_t d = 0; d < spec.delta_deg.size(); d += every) {
      const double delta = spec.delta_deg[d];
      SeedGroup group{spec.gamma_deg[g], delta, 0, spec.readings_per_delta, {}};
      group.poses = SpaceFilling(spec, rig, group.gamma_deg, delta, spec.readings_per_delta);
      OrderForTravel(group.poses);
      groups.push_back(std::move(group));
    }
  }
  std::vector<Pose> retro = RetroScan(spec, rig);
  if (!retro.empty()) {
    auto at_zero = std::find_if(groups.begin(), groups.end(), [&](const SeedGroup& s) {
      return s.gamma_deg == spec.gamma_deg.front() && s.delta_deg == 0;
    });
    if (at_zero == groups.end()) {
      at_zero = groups.insert(groups.begin(), SeedGroup{spec.gamma_deg.front(), 0, 0, 0, {}});
    }
    at_zero->retro_poses = static_cast<int>(retro.size());
    at_zero->poses.insert(at_zero->poses.begin(), retro.begin(), retro.end());
  }
  if (rig.has_gamma_axis) {
    std::stable_sort(groups.begin(), groups.end(), [](const SeedGroup& a, const SeedGroup& b) {
      return a.delta_deg < b.delta_deg;
    });
  }
  return groups;
}

std::vector<Pose> SeedPoses(const std::vector<SeedGroup>& groups) {
  std::vector<Pose> poses;
  for (const SeedGroup& g : groups) poses.insert(poses.end(), g.poses.begin(), g.poses.end());
  return poses;
}

}  // namespace brdf::adaptive
