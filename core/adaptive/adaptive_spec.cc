#include "core/adaptive/adaptive_spec.h"

#include <cmath>

#include "core/geometry.h"

namespace brdf::adaptive {
namespace {

Region ResolveRegion(const v1::AdaptiveRegion& r) {
  Region region;
  if (r.has_theta_i_min_deg()) region.theta_i_min_deg = r.theta_i_min_deg();
  if (r.has_theta_i_max_deg()) region.theta_i_max_deg = r.theta_i_max_deg();
  if (r.has_theta_o_min_deg()) region.theta_o_min_deg = r.theta_o_min_deg();
  if (r.has_theta_o_max_deg()) region.theta_o_max_deg = r.theta_o_max_deg();
  return region;
}

std::vector<double> ResolveDeltas(const v1::AngleRange& range) {
  const GridSpec paper;
  const double start = range.has_start() ? range.start() : paper.delta_start_deg;
  const double stop = range.has_stop() ? range.stop() : paper.delta_stop_deg;
  const double step = range.has_step() ? range.step() : paper.delta_step_deg;
  std::vector<double> values;
  if (!(step > 0) || !std::isfinite(start) || !std::isfinite(stop)) return values;
  const double count = std::floor((stop - start + 1e-9) / step) + 1;
  for (double i = 0; i < count; ++i) values.push_back(start + i * step);
  return values;
}

}  // namespace

bool RegionContains(const Region& region, const Directions& d) {
  constexpr double kSlack = 1e-9;
  return d.theta_i >= region.theta_i_min_deg - kSlack &&
         d.theta_i <= region.theta_i_max_deg + kSlack &&
         d.theta_o >= region.theta_o_min_deg - kSlack &&
         d.theta_o <= region.theta_o_max_deg + kSlack;
}

AdaptiveSpec ResolveAdaptive(const v1::Adaptive& adaptive) {
  AdaptiveSpec spec;
  const v1::AdaptiveTarget& t = adaptive.target();
  if (t.has_expected_error()) {
    spec.target = {TargetKind::kExpectedError, t.expected_error()};
  } else {
    spec.target = {TargetKind::kExpandedUncertainty, t.expanded_uncertainty()};
  }
  spec.budget.max_readings = static_cast<int>(adaptive.budget().max_readings());
  spec.budget.max_rig_s = adaptive.budget().max_rig_minutes() * 60;
  spec.budget.max_prompts = static_cast<int>(adaptive.budget().max_prompts());
  spec.region = ResolveRegion(adaptive.region());
  spec.judge = adaptive.method() == v1::ADAPTIVE_JUDGE_DELAUNAY ? Judge::kDelaunay : Judge::kOctant;
  spec.sample_fixed = adaptive.has_sample_fixed();
  if (adaptive.sample_fixed().seed_readings() != 0) {
    spec.fixed_seed_readings = static_cast<int>(adaptive.sample_fixed().seed_readings());
  }
  if (!spec.sample_fixed) spec.delta_deg = ResolveDeltas(adaptive.delta());
  if (adaptive.gamma_size() > 0)
    spec.gamma_deg.assign(adaptive.gamma().begin(), adaptive.gamma().end());
  if (adaptive.seed().has_retro_readings()) {
    spec.retro_readings = static_cast<int>(adaptive.seed().retro_readings());
  }
  if (adaptive.seed().readings_per_delta() != 0) {
    spec.readings_per_delta = static_cast<int>(adaptive.seed().readings_per_delta());
  }
  if (adaptive.seed().delta_every() != 0) {
    spec.seed_delta_every = static_cast<int>(adaptive.seed().delta_every());
  }
  if (adaptive.round_readings() != 0) {
    spec.round_readings = static_cast<int>(adaptive.round_readings());
  }
  return spec;
}

}  // namespace brdf::adaptive
