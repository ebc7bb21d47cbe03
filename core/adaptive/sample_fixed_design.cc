#include "core/adaptive/sample_fixed_design.h"

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <numbers>
#include <optional>

#include "core/adaptive/prompt_order.h"
#include "core/geometry.h"
#include "core/plan/expand_steps.h"
#include "core/plan/plan_settings.h"

namespace brdf::adaptive {
namespace {

constexpr unsigned kDrawsPerPose = 512;

double ToDeg(double rad) {
  return rad * 180 / std::numbers::pi;
}

double SinSquared(double deg) {
  const double s = std::sin(deg * std::numbers::pi / 180);
  return s * s;
}

// θ with sin²θ at fraction u of the way between the limits' sin².
double SpreadTheta(double u, double min_deg, double max_deg) {
  const double lo = SinSquared(min_deg);
  const double hi = SinSquared(max_deg);
  return ToDeg(std::asin(std::sqrt(lo + u * (hi - lo))));
}

// A direction pair rounded to whole degrees (φ = 0 on the normal); nullopt outside the region.
std::optional<Pose> HandSet(const Region& region, double theta_i, double theta_o, double phi) {
  IsoDirection d{std::round(theta_i), std::round(theta_o), std::round(phi)};
  if (d.theta_i == 0 || d.theta_o == 0) d.phi = 0;
  if (!RegionContains(region, CanonicalDirections(d))) return std::nullopt;
  Result<Pose> pose = FixedPose(d);
  if (!pose.ok()) return std::nullopt;
  return *pose;
}

bool Has(const std::vector<Pose>& poses, const Pose& p) {
  return std::find(poses.begin(), poses.end(), p) != poses.end();
}

std::vector<Pose> RetroScan(const AdaptiveSpec& spec) {
  std::vector<Pose> poses;
  const Region& r = spec.region;
  const double lo = std::max(r.theta_i_min_deg, r.theta_o_min_deg);
  const double hi = std::min(r.theta_i_max_deg, r.theta_o_max_deg);
  const int n = spec.retro_readings;
  for (int i = 0; i < n && hi >= lo; ++i) {
    const double theta = n == 1 ? (lo + hi) / 2 : lo + (hi - lo) * i / (n - 1);
    // Whole degrees where they stay in the region, else the scan's own angle.
    std::optional<Pose> pose = HandSet(r, theta, theta, 0);
    if (!pose.has_value()) {
      const Result<Pose> exact = FixedPose({theta, theta, 0});
      if (exact.ok()) pose = *exact;
    }
    if (pose.has_value() && !Has(poses, *pose)) poses.push_back(*pose);
  }
  return poses;
}

std::vector<Pose> SpaceFilling(const AdaptiveSpec& spec, const std::vector<Pose>& taken) {
  std::vector<Pose> poses;
  const Region& r = spec.region;
  const int wanted = spec.fixed_seed_readings;
  const unsigned draws = kDrawsPerPose * static_cast<unsigned>(std::max(wanted, 1));
  for (unsigned k = 1; k <= draws && static_cast<int>(poses.size()) < wanted; ++k) {
    const std::optional<Pose> pose =
        HandSet(r, SpreadTheta(RadicalInverse(k, 2), r.theta_i_min_deg, r.theta_i_max_deg),
                SpreadTheta(RadicalInverse(k, 3), r.theta_o_min_deg, r.theta_o_max_deg),
                180 * RadicalInverse(k, 5));
    if (pose.has_value() && !Has(taken, *pose) && !Has(poses, *pose)) poses.push_back(*pose);
  }
  return poses;
}

// start, start + step, … ≤ stop, and stop itself.
std::vector<double> Lattice(double start, double stop, double step) {
  std::vector<double> values;
  for (int k = 0; start + k * step <= stop + 1e-9; ++k) values.push_back(start + k * step);
  if (values.empty() || values.back() < stop - 1e-9) values.push_back(stop);
  return values;
}

}  // namespace

Result<Pose> FixedPose(const IsoDirection& target) {
  return InverseKinematics(target);
}

IsoDirection FixedTarget(const Pose& model) {
  const IsoDirection d = ToIsotropic(PoseToDirections(model));
  auto round6 = [](double deg) { return std::round(deg * 1e6) / 1e6; };
  return {round6(d.theta_i), round6(d.theta_o), round6(d.phi)};
}

SeedGroup FixedSeedDesign(const AdaptiveSpec& spec) {
  SeedGroup group{0, 0, 0, spec.fixed_seed_readings, {}};
  group.poses = RetroScan(spec);
  group.retro_poses = static_cast<int>(group.poses.size());
  const Pose from = group.poses.empty() ? Pose{} : group.poses.back();
  const std::vector<Pose> filling = SpaceFilling(spec, group.poses);
  for (const Pose& p : OrderForPrompts(from, filling)) group.poses.push_back(p);
  return group;
}

std::vector<Pose> FixedCandidates(const AdaptiveSpec& spec) {
  std::vector<Pose> out;
  const Region& r = spec.region;
  for (double ti : Lattice(r.theta_i_min_deg, r.theta_i_max_deg, kCandidateStepDeg)) {
    for (double to : Lattice(r.theta_o_min_deg, r.theta_o_max_deg, kCandidateStepDeg)) {
      const bool on_normal = ti == 0 || to == 0;
      for (double phi : Lattice(0, on_normal ? 0 : 180, kFixedCandidatePhiStepDeg)) {
        const Result<Pose> pose = FixedPose({ti, to, phi});
        if (pose.ok()) out.push_back(*pose);
      }
    }
  }
  return out;
}

PoseCost FixedPoseCost(const v1::Plan& plan, const plan::RigDescription& rig) {
  v1::Plan probe = plan;
  probe.clear_method();
  v1::SampleFixed* fixed = probe.mutable_sample_fixed();
  for (double theta : {30.0, 45.0}) {
    v1::DirectionTarget* t = fixed->add_targets();
    t->set_theta_i(theta);
    t->set_theta_o(theta);
    t->set_phi(180);
  }
  plan::RigDescription real = rig;
  real.time_scale = 1;
  // After the first reading, up to and including the second.
  return CostAfterFirstReading(probe, plan, real, true);
}

}  // namespace brdf::adaptive
