// An adaptive plan (brdf.v1.Adaptive) with every default filled in: the one place where the
// adaptive method's defaults are defined (as plan_settings.h is for the other methods). Does not
// validate: CheckPlanFields (core/plan/check_fields.h) reports out-of-range values with their
// field paths; ResolveAdaptive passes them through as given.
#pragma once

#include <vector>

#include "brdf/v1/plan.pb.h"
#include "core/pose.h"

namespace brdf::adaptive {

// Defaults of brdf.v1.Adaptive (plan.proto documents each).
inline constexpr double kDefaultThetaMaxDeg = 80;
inline constexpr int kDefaultRetroReadings = 8;
inline constexpr int kDefaultReadingsPerDelta = 12;
inline constexpr int kDefaultRoundReadings = 24;
// Caps that keep validation quick: (δ, γ) settings of one plan, and space-filling seed readings
// asked for in all.
inline constexpr int kMaxSeedSettings = 400;
inline constexpr int kMaxSeedReadings = 20000;
// Spacing of the candidate poses a round chooses from (candidates.h), degrees.
inline constexpr double kCandidateStepDeg = 5;
// The sample-fixed form's seed size (brdf.v1.AdaptiveSampleFixed.seed_readings) and its
// candidate direction pairs' spacing in the relative azimuth φ, degrees (θi and θo:
// kCandidateStepDeg; sample_fixed_design.h).
inline constexpr int kDefaultFixedSeedReadings = 12;
inline constexpr double kFixedCandidatePhiStepDeg = 10;

// Where readings may go: both polar angles within their limits (degrees).
struct Region {
  double theta_i_min_deg = 0;
  double theta_i_max_deg = kDefaultThetaMaxDeg;
  double theta_o_min_deg = 0;
  double theta_o_max_deg = kDefaultThetaMaxDeg;
};

// True when both polar angles of `d` lie within the region's limits (1e-9° of slack).
bool RegionContains(const Region& region, const Directions& d);

// What to reach: a relative level of one quantity, integrated cosine-weighted over the region.
enum class TargetKind { kExpandedUncertainty, kExpectedError };
struct Target {
  TargetKind kind = TargetKind::kExpandedUncertainty;
  double level = 0;  // relative, e.g. 0.05
};

// Limits of a session; 0 means "no limit of its own".
struct Budget {
  int max_readings = 0;
  double max_rig_s = 0;
  int max_prompts = 0;
  bool any() const { return max_readings > 0 || max_rig_s > 0 || max_prompts > 0; }
};

enum class Judge { kOctant, kDelaunay };

// Why an adaptive session stops (stop_rule.h); kContinue while it goes on.
enum class StopReason {
  kContinue,
  kTargetReached,  // the uncertainty left is at or below the target's level
  kReadingBudget,  // budget.maxReadings reached, or no reading fits in what is left of it
  kTimeBudget,     // budget.maxRigMinutes reached, or no reading fits in what is left of it
  kPromptBudget,   // budget.maxPrompts reached, or no reading fits in what is left of it
  kNothingToGain,  // no candidate within the budget is predicted to lower the uncertainty
};

struct AdaptiveSpec {
  // The sample-fixed method's form (plan.proto: AdaptiveSampleFixed): lamp and detector placed by
  // hand at each pose's directions, a prompt per pose; delta_deg is then empty and gamma_deg {0}.
  bool sample_fixed = false;
  int fixed_seed_readings = kDefaultFixedSeedReadings;  // sample-fixed: space-filling seed poses
  Target target;
  Budget budget;
  Region region;
  Judge judge = Judge::kOctant;
  std::vector<double> delta_deg;        // the detector positions the design may use, ascending
                                        // (empty for the sample-fixed form)
  std::vector<double> gamma_deg = {0};  // dial positions
  int retro_readings = kDefaultRetroReadings;
  int readings_per_delta = kDefaultReadingsPerDelta;
  int seed_delta_every = 1;  // the seed's space-filling set at every n-th δ of delta_deg
  int round_readings = kDefaultRoundReadings;
};

// The spec of `plan.adaptive()` with defaults. The δ sweep is expanded as geometry.h's sweeps
// are (start, start + step, … ≤ stop); call it only with a checked plan (a bounded sweep).
AdaptiveSpec ResolveAdaptive(const v1::Adaptive& adaptive);

}  // namespace brdf::adaptive
