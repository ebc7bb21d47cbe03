// A stand-in uncertainty model for the planner's tests: the uncertainty over a grid of isotropic
// directions starts at a given field u0 and each reading (or assumed pick) takes away a share of
// it near its direction, with a Gaussian kernel in (θi, θo, φ/2) degrees. Remaining is the
// cosine-weighted mean. Not a model of the real uncertainty; it only has the right shape.
#pragma once

#include <cmath>
#include <functional>
#include <memory>
#include <numbers>
#include <span>
#include <vector>

#include "core/adaptive/uncertainty_model.h"
#include "core/geometry.h"

namespace brdf::adaptive::testing {

inline double IsoDistanceSquared(const IsoDirection& a, const IsoDirection& b) {
  const double di = a.theta_i - b.theta_i;
  const double d_o = a.theta_o - b.theta_o;
  const double dp = (a.phi - b.phi) / 2;
  return di * di + d_o * d_o + dp * dp;
}

class KernelMap : public UncertaintyMap {
 public:
  KernelMap(std::vector<IsoDirection> grid, std::vector<double> u, double sigma, double share)
      : grid_(std::move(grid)), u_(std::move(u)), sigma_(sigma), share_(share) {
    for (const IsoDirection& g : grid_) {
      weight_.push_back(std::cos(g.theta_i * std::numbers::pi / 180) *
                        std::cos(g.theta_o * std::numbers::pi / 180));
      total_ += weight_.back();
    }
  }
  double Remaining() const override {
    double sum = 0;
    for (std::size_t i = 0; i < grid_.size(); ++i) sum += weight_[i] * u_[i];
    return sum / total_;
  }
  double PredictedGain(const Directions& candidate) const override {
    const IsoDirection c = ToIsotropic(candidate);
    double sum = 0;
    for (std::size_t i = 0; i < grid_.size(); ++i) sum += weight_[i] * u_[i] * share_ * K(c, i);
    return sum / total_;
  }
  void Assume(const Directions& chosen) override { Apply(ToIsotropic(chosen)); }
  void Apply(const IsoDirection& at) {
    for (std::size_t i = 0; i < grid_.size(); ++i) u_[i] *= 1 - share_ * K(at, i);
  }

 private:
  double K(const IsoDirection& c, std::size_t i) const {
    return std::exp(-IsoDistanceSquared(c, grid_[i]) / (2 * sigma_ * sigma_));
  }
  std::vector<IsoDirection> grid_;
  std::vector<double> u_;
  std::vector<double> weight_;
  double total_ = 0;
  double sigma_;
  double share_;
};

class KernelModel : public UncertaintyModel {
 public:
  explicit KernelModel(std::function<double(const IsoDirection&)> u0, double sigma = 10,
                       double share = 0.8)
      : u0_(std::move(u0)), sigma_(sigma), share_(share) {}
  std::unique_ptr<UncertaintyMap> Map(std::span<const ReadingSoFar> readings) const override {
    std::vector<IsoDirection> grid;
    std::vector<double> u;
    for (double ti = 5; ti < 80; ti += 10) {
      for (double to = 5; to < 80; to += 10) {
        for (double phi = 0; phi <= 180; phi += 20) {
          grid.push_back({ti, to, phi});
          u.push_back(u0_(grid.back()));
        }
      }
    }
    auto map = std::make_unique<KernelMap>(std::move(grid), std::move(u), sigma_, share_);
    for (const ReadingSoFar& r : readings) map->Apply(ToIsotropic(r.directions));
    return map;
  }

 private:
  std::function<double(const IsoDirection&)> u0_;
  double sigma_;
  double share_;
};

}  // namespace brdf::adaptive::testing
