#include "core/adaptive/prompt_order.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstddef>
#include <numbers>
#include <tuple>

#include "core/geometry.h"

namespace brdf::adaptive {
namespace {

using Vec = std::array<double, 3>;

Vec Unit(double theta_deg, double phi_deg) {
  const double t = theta_deg * std::numbers::pi / 180;
  const double p = phi_deg * std::numbers::pi / 180;
  return {std::sin(t) * std::cos(p), std::sin(t) * std::sin(p), std::cos(t)};
}

double AngleDeg(const Vec& a, const Vec& b) {
  const double dot = a[0] * b[0] + a[1] * b[1] + a[2] * b[2];
  return std::acos(std::clamp(dot, -1.0, 1.0)) * 180 / std::numbers::pi;
}

auto IsoKey(const Pose& p) {
  const IsoDirection d = ToIsotropic(PoseToDirections(p));
  return std::make_tuple(d.theta_i, d.theta_o, d.phi);
}

// Nearest neighbour from `from`; ties to the smaller (θi, θo, φ).
std::vector<Pose> NearestNeighbour(const Pose& from, std::span<const Pose> poses) {
  std::vector<Pose> left(poses.begin(), poses.end());
  std::vector<Pose> out;
  Pose at = from;
  while (!left.empty()) {
    std::size_t best = 0;
    double best_d = SettingTravel(at, left[0]);
    for (std::size_t i = 1; i < left.size(); ++i) {
      const double d = SettingTravel(at, left[i]);
      if (d < best_d || (d == best_d && IsoKey(left[i]) < IsoKey(left[best]))) {
        best = i;
        best_d = d;
      }
    }
    at = left[best];
    out.push_back(at);
    left.erase(left.begin() + static_cast<std::ptrdiff_t>(best));
  }
  return out;
}

// 2-opt on the open path from `from`: reverses order[i..j] while that shortens the travel.
void TwoOpt(const Pose& from, std::vector<Pose>& order) {
  const std::size_t n = order.size();
  auto before = [&](std::size_t i) -> const Pose& { return i == 0 ? from : order[i - 1]; };
  for (int pass = 0; pass < kMaxOrderPasses; ++pass) {
    bool improved = false;
    for (std::size_t i = 0; i + 1 < n; ++i) {
      for (std::size_t j = i + 1; j < n; ++j) {
        const double now = SettingTravel(before(i), order[i]) +
                           (j + 1 < n ? SettingTravel(order[j], order[j + 1]) : 0);
        const double then = SettingTravel(before(i), order[j]) +
                            (j + 1 < n ? SettingTravel(order[i], order[j + 1]) : 0);
        if (then < now - 1e-9) {
          std::reverse(order.begin() + static_cast<std::ptrdiff_t>(i),
                       order.begin() + static_cast<std::ptrdiff_t>(j) + 1);
          improved = true;
        }
      }
    }
    if (!improved) break;
  }
}

}  // namespace

double SettingTravel(const Pose& a, const Pose& b) {
  const IsoDirection x = ToIsotropic(PoseToDirections(a));
  const IsoDirection y = ToIsotropic(PoseToDirections(b));
  return AngleDeg(Unit(x.theta_i, 0), Unit(y.theta_i, 0)) +
         AngleDeg(Unit(x.theta_o, x.phi), Unit(y.theta_o, y.phi));
}

double PromptTravel(const Pose& from, std::span<const Pose> poses) {
  double total = 0;
  Pose at = from;
  for (const Pose& p : poses) {
    total += SettingTravel(at, p);
    at = p;
  }
  return total;
}

std::vector<Pose> OrderForPrompts(const Pose& from, std::span<const Pose> poses) {
  std::vector<Pose> order = NearestNeighbour(from, poses);
  TwoOpt(from, order);
  if (PromptTravel(from, order) < PromptTravel(from, poses)) return order;
  return {poses.begin(), poses.end()};
}

void OrderRoundForPrompts(Round& round, const Pose& from) {
  std::vector<Pose> poses;
  for (const ChosenPose& c : round.poses) poses.push_back(c.pose);
  std::vector<ChosenPose> ordered;
  for (const Pose& p : OrderForPrompts(from, poses)) {
    const auto it = std::find_if(round.poses.begin(), round.poses.end(),
                                 [&](const ChosenPose& c) { return c.pose == p; });
    ordered.push_back(*it);
  }
  round.poses = std::move(ordered);
}

}  // namespace brdf::adaptive
