// The plans the tests submit, in their JSON form (docs: core/plan/plan_json.h), built in one place.
// A fixture is a PlanFixture value: start from one of the named plans below, change what a test
// needs (`.Retry(3, 100)`, `.Measurement(100, 1)`, …) and take `.Json()`. Every test that used to
// carry its own copy of a plan now names it here, with the values it asserted on.
#pragma once

#include <optional>
#include <string>
#include <vector>

namespace brdf::testing {

struct PlanRange {
  double start = 0;
  double stop = 0;
  double step = 0;
};

struct PlanPose {
  double alpha = 0;
  double beta = 0;
  double delta = 0;
};

struct PlanTarget {
  double theta_i = 0;
  double theta_o = 0;
  double phi = 0;
  std::string label;
};

class PlanFixture {
 public:
  explicit PlanFixture(std::string name) : name_(std::move(name)) {}

  PlanFixture& Name(std::string name) {
    name_ = std::move(name);
    return *this;
  }
  // The pose mode (one of the three).
  PlanFixture& SampleRotation(PlanRange delta, PlanRange alpha, double beta_step,
                              std::optional<double> theta_max_deg = std::nullopt);
  PlanFixture& PoseList(std::vector<PlanPose> poses);
  PlanFixture& SampleFixed(std::vector<PlanTarget> targets);

  // Optional sections; left out of the JSON unless set.
  PlanFixture& Reference(bool per_detector_position);
  PlanFixture& DarkWithEachReference();
  PlanFixture& Measurement(int integration_ms, int averages);
  PlanFixture& Retry(int max_attempts, int backoff_ms);

  std::string Json() const;
  operator std::string() const { return Json(); }  // NOLINT: fixtures read as plan text

 private:
  std::string name_;
  std::string mode_;  // the pose mode's JSON member, ready to print
  std::optional<bool> reference_per_detector_;
  bool dark_with_reference_ = false;
  std::optional<std::pair<int, int>> measurement_;
  std::optional<std::pair<int, int>> retry_;
};

namespace plans {

// Two detector positions (22.5°, 45°), two tilts (0°, 20°), β every 45°; a reference per
// detector position and a dark with each; 200 ms × 1; 2 attempts.
PlanFixture SmallRotation();
// One detector position, β every `beta_step`° over α 0…`alpha_stop`, readings of 200 ms ×
// `averages` (long enough to pause in the middle); 2 attempts.
PlanFixture SlowRotation(double alpha_stop, double beta_step, int averages);
// Sample fixed at the given targets (operator prompts for each); 200 ms × 1; 2 attempts.
PlanFixture SampleFixed(std::vector<PlanTarget> targets, bool reference_per_detector_position);
// Two poses at δ 40°: (α 0, β 10), (α 10, β 20); 100 ms × 1; 2 attempts.
PlanFixture TinyPoseList();
// One pose (α 0, β 10, δ 40), nothing else: a session that only has to exist or queue.
PlanFixture OnePose();
// δ 30…45 by 15, α 0…20 by 10, β every 10° to θmax 40°; a reference per detector position and a
// dark with each: enough readings to interpolate and export.
PlanFixture InterpolationGrid();

// An anisotropic plan of two poses at γ = 0 ((α, β, δ) = (0, 10, 40), (10, 20, 40)), 100 ms × 1,
// no reference (radiance only): the smallest session an anisotropic refusal is tested on. JSON.
std::string TwoAnisotropicPoses(const std::string& name);

}  // namespace plans
}  // namespace brdf::testing
