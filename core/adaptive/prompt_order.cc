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

// The travels between `from` (index 0) and the poses (1 … n), computed once.
class Travels {
 public:
  Travels(const Pose& from, std::span<const Pose> poses) : n_(poses.size() + 1), d_(n_ * n_) {
    std::vector<Pose> all = {from};
    all.insert(all.end(), poses.begin(), poses.end());
    for (std::size_t i = 0; i < n_; ++i) {
      for (std::size_t j = i + 1; j < n_; ++j) {
        d_[i * n_ + j] = d_[j * n_ + i] = SettingTravel(all[i], all[j]);
      }
    }
  }
  double operator()(std::size_t a, std::size_t b) const { return d_[a * n_ + b]; }

 private:
  std::size_t n_;
  std::vector<double> d_;
};

// Nearest neighbour from index 0 over indexes 1 … n; ties to the smaller (θi, θo, φ).
std::vector<std::size_t> NearestNeighbour(const Travels& travel, std::span<const Pose> poses) {
  std::vector<std::size_t> left;
  for (std::size_t i = 1; i <= poses.size(); ++i) left.push_back(i);
  std::vector<std::size_t> out;
  std::size_t at = 0;
  while (!left.empty()) {
    std::size_t best = 0;
    for (std::size_t k = 1; k < left.size(); ++k) {
      const double d = travel(at, left[k]);
      const double best_d = travel(at, left[best]);
      if (d < best_d ||
          (d == best_d && IsoKey(poses[left[k] - 1]) < IsoKey(poses[left[best] - 1]))) {
        best = k;
      }
    }
    at = left[best];
    out.push_back(at);
    left.erase(left.begin() + static_cast<std::ptrdiff_t>(best));
  }
  return out;
}

// 2-opt on the open path from index 0: reverses order[i..j] while that shortens the travel.
void TwoOpt(const Travels& travel, std::vector<std::size_t>& order) {
  const std::size_t n = order.size();
  auto before = [&](std::size_t i) { return i == 0 ? std::size_t{0} : order[i - 1]; };
  for (int pass = 0; pass < kMaxOrderPasses; ++pass) {
    bool improved = false;
    for (std::size_t i = 0; i + 1 < n; ++i) {
      for (std::size_t j = i + 1; j < n; ++j) {
        const double tail_now = j + 1 < n ? travel(order[j], order[j + 1]) : 0;
        const double tail_then = j + 1 < n ? travel(order[i], order[j + 1]) : 0;
        const double now = travel(before(i), order[i]) + tail_now;
        const double then = travel(before(i), order[j]) + tail_then;
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
  const Travels travel(from, poses);
  std::vector<std::size_t> order = NearestNeighbour(travel, poses);
  TwoOpt(travel, order);
  std::vector<Pose> out;
  for (std::size_t i : order) out.push_back(poses[i - 1]);
  if (PromptTravel(from, out) < PromptTravel(from, poses)) return out;
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
