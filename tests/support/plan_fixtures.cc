#include "tests/support/plan_fixtures.h"

#include <sstream>

namespace brdf::testing {
namespace {

std::string Range(const PlanRange& r) {
  std::ostringstream o;
  o << "{\"start\": " << r.start << ", \"stop\": " << r.stop << ", \"step\": " << r.step << "}";
  return o.str();
}

}  // namespace

PlanFixture& PlanFixture::SampleRotation(PlanRange delta, PlanRange alpha, double beta_step,
                                         std::optional<double> theta_max_deg) {
  std::ostringstream o;
  o << "\"sampleRotation\": {\n    \"delta\": " << Range(delta)
    << ",\n    \"alpha\": " << Range(alpha) << ",\n    \"beta\": {\"step\": " << beta_step;
  if (theta_max_deg.has_value()) o << ", \"thetaMaxDeg\": " << *theta_max_deg;
  o << "}\n  }";
  mode_ = o.str();
  return *this;
}

PlanFixture& PlanFixture::PoseList(std::vector<PlanPose> poses) {
  std::ostringstream o;
  o << "\"poseList\": {\"poses\": [";
  for (std::size_t i = 0; i < poses.size(); ++i) {
    o << (i ? ", " : "") << "{\"alpha\": " << poses[i].alpha << ", \"beta\": " << poses[i].beta
      << ", \"delta\": " << poses[i].delta << "}";
  }
  o << "]}";
  mode_ = o.str();
  return *this;
}

PlanFixture& PlanFixture::SampleFixed(std::vector<PlanTarget> targets) {
  std::ostringstream o;
  o << "\"sampleFixed\": {\n    \"targets\": [";
  for (std::size_t i = 0; i < targets.size(); ++i) {
    const PlanTarget& t = targets[i];
    o << (i ? "," : "") << "\n      {\"thetaI\": " << t.theta_i << ", \"thetaO\": " << t.theta_o
      << ", \"phi\": " << t.phi << ", \"label\": \"" << t.label << "\"}";
  }
  o << "\n    ]\n  }";
  mode_ = o.str();
  return *this;
}

PlanFixture& PlanFixture::Reference(bool per_detector_position) {
  reference_per_detector_ = per_detector_position;
  return *this;
}

PlanFixture& PlanFixture::DarkWithEachReference() {
  dark_with_reference_ = true;
  return *this;
}

PlanFixture& PlanFixture::Measurement(int integration_ms, int averages) {
  measurement_ = std::make_pair(integration_ms, averages);
  return *this;
}

PlanFixture& PlanFixture::Retry(int max_attempts, int backoff_ms) {
  retry_ = std::make_pair(max_attempts, backoff_ms);
  return *this;
}

std::string PlanFixture::Json() const {
  std::ostringstream o;
  o << "{\n  \"name\": \"" << name_ << "\"";
  if (!mode_.empty()) o << ",\n  " << mode_;
  if (reference_per_detector_.has_value()) {
    o << ",\n  \"reference\": {\"perDetectorPosition\": "
      << (*reference_per_detector_ ? "true" : "false") << "}";
  }
  if (dark_with_reference_) o << ",\n  \"dark\": {\"withEachReference\": true}";
  if (measurement_.has_value()) {
    o << ",\n  \"measurement\": {\"integrationMs\": " << measurement_->first
      << ", \"averages\": " << measurement_->second << "}";
  }
  if (retry_.has_value()) {
    o << ",\n  \"retry\": {\"maxAttempts\": " << retry_->first
      << ", \"backoffMs\": " << retry_->second << "}";
  }
  o << "\n}";
  return o.str();
}

namespace plans {

PlanFixture SmallRotation() {
  return PlanFixture("small rotation")
      .SampleRotation({22.5, 45, 22.5}, {0, 20, 20}, 45)
      .Reference(true)
      .DarkWithEachReference()
      .Measurement(200, 1)
      .Retry(2, 0);
}

PlanFixture SlowRotation(double alpha_stop, double beta_step, int averages) {
  return PlanFixture("slow readings")
      .SampleRotation({30, 30, 10}, {0, alpha_stop, 10}, beta_step)
      .Measurement(200, averages)
      .Retry(2, 0);
}

PlanFixture SampleFixed(std::vector<PlanTarget> targets, bool reference_per_detector_position) {
  return PlanFixture("sample fixed")
      .SampleFixed(std::move(targets))
      .Reference(reference_per_detector_position)
      .Measurement(200, 1)
      .Retry(2, 0);
}

PlanFixture TinyPoseList() {
  return PlanFixture("tiny pose list")
      .PoseList({{0, 10, 40}, {10, 20, 40}})
      .Measurement(100, 1)
      .Retry(2, 0);
}

PlanFixture OnePose() {
  return PlanFixture("queued").PoseList({{0, 10, 40}});
}

PlanFixture InterpolationGrid() {
  return PlanFixture("interpolation grid")
      .SampleRotation({30, 45, 15}, {0, 20, 10}, 10, 40.0)
      .Reference(true)
      .DarkWithEachReference();
}

std::string TwoAnisotropicPoses(const std::string& name) {
  return R"({
  "name": ")" +
         name + R"(",
  "anisotropic": true,
  "poseList": {"poses": [{"alpha": 0, "beta": 10, "delta": 40}, {"alpha": 10, "beta": 20, "delta": 40}]},
  "measurement": {"integrationMs": 100, "averages": 1}
})";
}

}  // namespace plans
}  // namespace brdf::testing
