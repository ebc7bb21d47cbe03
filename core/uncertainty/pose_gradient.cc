#include "core/uncertainty/pose_gradient.h"

#include <algorithm>
#include <cmath>
#include <map>
#include <utility>

namespace brdf::uncertainty {
namespace {

constexpr double kRadPerDeg = 3.14159265358979323846 / 180.0;
constexpr double kSameDeg = 1e-3;  // axes closer than this are the same position

double AxisOf(const Pose& p, int axis) {
  switch (axis) {
    case 0:
      return p.alpha;
    case 1:
      return p.beta;
    case 2:
      return p.gamma;
    default:
      return p.delta;
  }
}

// The other three axes, rounded to kSameDeg: readings with equal keys lie on one line along axis.
std::array<long long, 3> LineKey(const Pose& p, int axis) {
  std::array<long long, 3> key{};
  for (int a = 0, k = 0; a < 4; ++a) {
    if (a != axis) key[k++] = std::llround(AxisOf(p, a) / kSameDeg);
  }
  return key;
}

bool Usable(const PosedValue& r, std::size_t bands) {
  return r.value.size() == bands && bands > 0 && std::isfinite(r.theta_i_deg) &&
         r.theta_i_deg >= 0 && r.theta_i_deg < 90;
}

// f · cos θi per band: what the meter's radiance is proportional to.
std::vector<double> RadianceFactor(const PosedValue& r) {
  std::vector<double> g = r.value;
  const double c = std::cos(r.theta_i_deg * kRadPerDeg);
  for (double& x : g) x *= c;
  return g;
}

// (position, index) of the readings on one line, sorted by position.
using Line = std::vector<std::pair<double, std::size_t>>;

// The mean radiance factor of the readings on `line` at the position of line[at] (repeats), and
// that position.
std::pair<std::vector<double>, double> MeanAt(const Line& line, std::size_t at,
                                              const std::vector<std::vector<double>>& factor) {
  const double here = line[at].first;
  std::vector<double> sum(factor[line[at].second].size(), 0.0);
  int count = 0;
  for (const auto& [position, index] : line) {
    if (std::abs(position - here) >= kSameDeg) continue;
    for (std::size_t k = 0; k < sum.size(); ++k) sum[k] += factor[index][k];
    ++count;
  }
  for (double& x : sum) x /= count;
  return {std::move(sum), here};
}

// The gradient of the reading at line[at] from the nearest positions below and above on `line`
// (each the mean of its repeats), or from its own position and the one neighbour at an edge.
std::vector<double> AlongLine(const Line& line, std::size_t at,
                              const std::vector<std::vector<double>>& factor, double cos_self) {
  const double here = line[at].first;
  std::size_t lo = at, hi = at;
  while (lo > 0 && line[lo].first > here - kSameDeg) --lo;
  while (hi + 1 < line.size() && line[hi].first < here + kSameDeg) ++hi;
  const bool has_lo = line[lo].first <= here - kSameDeg;
  const bool has_hi = line[hi].first >= here + kSameDeg;
  if (!has_lo && !has_hi) return {};
  const auto [below, p_below] = MeanAt(line, has_lo ? lo : at, factor);
  const auto [above, p_above] = MeanAt(line, has_hi ? hi : at, factor);
  std::vector<double> g(below.size());
  for (std::size_t k = 0; k < g.size(); ++k) {
    g[k] = (above[k] - below[k]) / (p_above - p_below) / cos_self;
  }
  return g;
}

}  // namespace

std::vector<PoseGradient> EstimatePoseGradients(std::span<const PosedValue> readings) {
  std::vector<PoseGradient> out(readings.size());
  if (readings.empty()) return out;
  const std::size_t bands = readings.front().value.size();
  std::vector<std::vector<double>> factor(readings.size());
  for (std::size_t i = 0; i < readings.size(); ++i) {
    if (Usable(readings[i], bands)) factor[i] = RadianceFactor(readings[i]);
  }
  for (int axis = 0; axis < 4; ++axis) {
    std::map<std::array<long long, 3>, Line> lines;
    for (std::size_t i = 0; i < readings.size(); ++i) {
      if (!factor[i].empty()) {
        lines[LineKey(readings[i].pose, axis)].emplace_back(AxisOf(readings[i].pose, axis), i);
      }
    }
    for (auto& [key, line] : lines) {
      std::sort(line.begin(), line.end());
      for (std::size_t at = 0; at < line.size(); ++at) {
        const std::size_t self = line[at].second;
        out[self][static_cast<std::size_t>(axis)] =
            AlongLine(line, at, factor, std::cos(readings[self].theta_i_deg * kRadPerDeg));
      }
    }
  }
  return out;
}

}  // namespace brdf::uncertainty
