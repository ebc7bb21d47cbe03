#include "core/plan/expand_steps.h"

#include <algorithm>
#include <optional>
#include <string>
#include <utility>

#include "core/adaptive/adaptive_spec.h"
#include "core/adaptive/sample_fixed_design.h"
#include "core/adaptive/seed_design.h"
#include "core/geometry.h"
#include "core/plan/angle_text.h"
#include "core/plan/check_fields.h"
#include "core/plan/plan_settings.h"
#include "core/plan/timing.h"

namespace brdf::plan {
namespace {

// Field paths to blame when a move goes beyond an axis' travel; empty: not checked here
// (CheckPlanFields already checked that axis).
struct AxisPaths {
  std::string alpha;
  std::string beta;
  std::string gamma;
};

std::string PoseText(const Pose& m) {
  return "δ " + Deg(m.delta) + " α " + Deg(m.alpha) + " β " + Deg(m.beta) + " γ " + Deg(m.gamma);
}

std::string TargetText(const Directions& d) {
  return "θi = " + Deg(d.theta_i) + ", φi = " + Deg(d.phi_i) + ", θo = " + Deg(d.theta_o) +
         ", φo = " + Deg(d.phi_o);
}

// Appends steps in order, keeps track of where the rig is (in model angles), of the timing
// estimate, and of when the next white reference is due.
class Builder {
 public:
  Builder(const v1::Plan& plan, const RigDescription& rig, ProblemSink& sink)
      : rig_(rig),
        settings_(ResolveSettings(plan)),
        sink_(sink),
        timer_(rig, settings_.measurement),
        sample_fixed_(SampleFixedMethod(plan)) {}

  // Continues after steps stored before (ExpandPosesFrom).
  void StartFrom(const ExpansionStart& start) {
    model_ = start.model;
    have_reference_ = start.have_reference;
    relocated_since_reference_ = start.relocated_since_reference;
    samples_since_reference_ = start.samples_since_reference;
    last_reference_s_ = -start.seconds_since_reference;
  }

  bool full() const { return steps_.size() > static_cast<std::size_t>(kMaxSteps); }
  const Pose& model() const { return model_; }
  std::vector<Step> Take() { return std::move(steps_); }

  // Turns the sample's dial: a prompt on a manual dial; on a motorized γ axis the next move
  // turns it.
  void DialTo(double gamma) {
    model_.gamma = gamma;
    if (rig_.has_gamma_axis) return;
    Prompt(
        v1::PROMPT_KIND_SET_GAMMA_DIAL, model_,
        "Turn the sample's dial to γ = " + Deg(gamma) + " (about the sample normal), then confirm.",
        "dial at γ = " + Deg(gamma), "dial to γ " + Deg(gamma));
  }

  // Relocates the detector: a prompt, or a move of the δ axis on a motorized arm.
  void DetectorTo(double delta) {
    Pose next = model_;
    next.delta = delta;
    if (rig_.has_detector_arm) {
      Move(next, "detector arm to δ " + Deg(delta), {});
    } else {
      model_ = next;
      Prompt(v1::PROMPT_KIND_RELOCATE_DETECTOR, next,
             "Move the detector to δ = " + Deg(delta) +
                 " (the lamp–sample–detector angle), aim it at the sample, then confirm.",
             "detector at δ = " + Deg(delta), "detector to δ " + Deg(delta));
    }
    relocated_since_reference_ = true;
  }

  // Sample-fixed: the operator moves lamp and detector to the target.
  void RelocateLampAndDetector(const Pose& model, const Directions& target, const std::string& what,
                               bool isotropic_form) {
    model_ = model;
    std::string where = TargetText(target);
    if (isotropic_form) {
      where = "θi = " + Deg(target.theta_i) + ", θo = " + Deg(target.theta_o) +
              ", relative azimuth φ = " + Deg(target.phi_o - target.phi_i);
    }
    Prompt(v1::PROMPT_KIND_RELOCATE_LAMP_AND_DETECTOR, model,
           what + ": place the lamp and the detector at " + where +
               " (polar angles from the sample normal), aim both at the sample, then confirm.",
           "lamp and detector at " + where, "relocate to " + what, target);
    relocated_since_reference_ = true;
  }

  // A sample reading at `model`, preceded by a white reference when one is due and, unless the
  // plan is sample-fixed, by a move to the pose.
  void Sample(const Pose& model, const Directions& target, const std::string& label,
              const AxisPaths& paths) {
    if (ReferenceDue()) ReferenceBlock(target);
    if (!sample_fixed_) Move(model, "move to " + PoseText(model), paths);
    model_ = model;
    Reading(v1::STEP_KIND_SAMPLE, model, target, label);
    ++samples_since_reference_;
  }

 private:
  void Emit(Step step) {
    if (full()) return;
    step.index = static_cast<int>(steps_.size());
    timer_.Advance(step);
    steps_.push_back(std::move(step));
  }

  Pose Readings(const Pose& model) const { return ToReadings(model, rig_.convention); }

  void Prompt(PromptKind kind, const Pose& model, std::string text, std::string expected,
              std::string label, std::optional<Directions> target = std::nullopt) {
    Step s;
    s.kind = v1::STEP_KIND_PROMPT;
    s.pose = Readings(model);
    s.prompt = kind;
    s.prompt_text = std::move(text);
    s.expected_action = std::move(expected);
    s.label = std::move(label);
    s.target = target;
    Emit(std::move(s));
  }

  void CheckTravel(const std::string& path, const char* axis, double reading,
                   const AxisTravel& travel, const std::string& where) {
    if (path.empty() || travel.Contains(reading)) return;
    sink_.AddOnce(path, std::string(axis) + " = " + Deg(reading) + " (" + where +
                            ") is beyond the " + axis + " axis' travel [" + Deg(travel.min_deg) +
                            ", " + Deg(travel.max_deg) +
                            "]; change the plan or the rig's travel limits");
  }

  void Move(const Pose& model, std::string label, const AxisPaths& paths) {
    Step s;
    s.kind = v1::STEP_KIND_MOVE;
    s.pose = Readings(model);
    CheckTravel(paths.alpha, "α", s.pose.alpha, rig_.alpha, label);
    CheckTravel(paths.beta, "β", s.pose.beta, rig_.beta, label);
    if (rig_.has_gamma_axis) CheckTravel(paths.gamma, "γ", s.pose.gamma, rig_.gamma, label);
    s.label = std::move(label);
    model_ = model;
    Emit(std::move(s));
  }

  void Reading(StepKind kind, const Pose& model, const Directions& target, std::string label) {
    Step s;
    s.kind = kind;
    s.pose = Readings(model);
    s.target = target;
    s.label = std::move(label);
    Emit(std::move(s));
  }

  bool ReferenceDue() const {
    const ReferenceSettings& r = settings_.reference;
    if (!have_reference_) return true;
    if (r.per_detector_position && relocated_since_reference_) return true;
    if (r.every_n_readings > 0 && samples_since_reference_ >= r.every_n_readings) return true;
    if (r.every_minutes > 0 &&
        timer_.elapsed_estimate_s() - last_reference_s_ >= r.every_minutes * 60) {
      return true;
    }
    return false;
  }

  // Mount white, [move to the reference pose], reference, [close shutter, dark], mount sample.
  // `sample_target` is the next sample's target: a sample-fixed reference is taken there.
  void ReferenceBlock(const Directions& sample_target) {
    const bool dark = settings_.reference.dark_with_each_reference;
    Prompt(v1::PROMPT_KIND_MOUNT_WHITE, model_,
           "Replace the sample with the white standard (same place, same orientation), then "
           "confirm.",
           "white standard mounted", "mount white");
    Pose at = model_;
    Directions target = sample_target;
    if (!sample_fixed_) {
      at = ReferencePose(settings_.reference, model_.gamma, model_.delta);
      target = PoseToDirections(at);
      if (target.theta_i > kReferenceThetaMaxDeg || target.theta_o > kReferenceThetaMaxDeg) {
        sink_.AddOnce("reference.pose",
                      "at δ = " + Deg(at.delta) + " the reference pose (α " + Deg(at.alpha) +
                          ", β " + Deg(at.beta) + ") puts the " +
                          (target.theta_i > kReferenceThetaMaxDeg ? "lamp" : "detector") +
                          " at θi = " + Deg(target.theta_i) + " / θo = " + Deg(target.theta_o) +
                          " from the white's normal (more than " + Deg(kReferenceThetaMaxDeg) +
                          "); give a reference.pose.beta that suits every δ, or leave it unset "
                          "for the automatic pose");
      }
      Move(at, "move to reference pose at δ " + Deg(at.delta),
           {"reference.pose.alpha", "reference.pose.beta", ""});
    }
    const std::string where = sample_fixed_ ? TargetText(target) : PoseText(at);
    Reading(v1::STEP_KIND_REFERENCE, at, target, "white reference at " + where);
    last_reference_s_ = timer_.elapsed_estimate_s();
    if (dark) {
      Prompt(v1::PROMPT_KIND_CLOSE_SHUTTER, at,
             "Close the lamp shutter (leave the white standard in place), then confirm.",
             "lamp shuttered", "close shutter");
      Reading(v1::STEP_KIND_DARK, at, target, "dark at " + where);
    }
    Prompt(v1::PROMPT_KIND_MOUNT_SAMPLE, at,
           dark ? "Open the lamp shutter and replace the white standard with the sample, then "
                  "confirm."
                : "Replace the white standard with the sample, then confirm.",
           dark ? "shutter open, sample mounted" : "sample mounted", "mount sample");
    have_reference_ = true;
    relocated_since_reference_ = false;
    samples_since_reference_ = 0;
  }

  const RigDescription& rig_;
  const PlanSettings settings_;
  ProblemSink& sink_;
  StepTimer timer_;
  const bool sample_fixed_;
  std::vector<Step> steps_;

  Pose model_;  // where the rig is, in model angles (starts at 0)
  bool have_reference_ = false;
  bool relocated_since_reference_ = false;
  std::uint32_t samples_since_reference_ = 0;
  double last_reference_s_ = 0;
};

void ExpandSampleRotation(const v1::SampleRotation& rotation, const RigDescription& rig, Builder& b,
                          ProblemSink& sink) {
  const GridSpec spec = ResolveGridSpec(rotation);
  // Model angles: the convention is applied when steps are emitted.
  Result<std::vector<Pose>> grid = ExpandSampleRotationGrid(spec);
  if (!grid.ok()) {
    sink.Add("sampleRotation", grid.status().message());
    return;
  }
  // Rows of constant (γ, δ, α), β ascending, in geometry.h's order (γ, δ, α outermost first).
  struct Row {
    std::vector<Pose> poses;
  };
  std::vector<Row> rows;
  for (const Pose& p : *grid) {
    if (rows.empty() || rows.back().poses.front().gamma != p.gamma ||
        rows.back().poses.front().delta != p.delta || rows.back().poses.front().alpha != p.alpha) {
      rows.push_back({});
    }
    rows.back().poses.push_back(p);
  }
  // With a motorized γ the detector is the only manual axis: relocate it least often (δ
  // outermost). With a manual dial, turn the dial least often (γ outermost, as generated).
  if (rig.has_gamma_axis) {
    std::stable_sort(rows.begin(), rows.end(), [](const Row& x, const Row& y) {
      return x.poses.front().delta < y.poses.front().delta;
    });
  }
  const bool dial_in_use =
      !rig.has_gamma_axis && !(spec.gamma_deg.size() == 1 && spec.gamma_deg[0] == 0);
  const AxisPaths paths{"", "sampleRotation.beta", ""};
  bool first = true;
  for (std::size_t r = 0; r < rows.size() && !b.full(); ++r) {
    const Pose& head = rows[r].poses.front();
    // A manual dial is turned by prompt; a motorized γ (or γ = 0 throughout) rides on the moves.
    if (dial_in_use && (first || head.gamma != b.model().gamma)) b.DialTo(head.gamma);
    if (first || head.delta != b.model().delta) b.DetectorTo(head.delta);
    first = false;
    // Serpentine: even rows run β upwards, odd rows downwards, so the β stage never rewinds.
    std::vector<Pose> row = rows[r].poses;
    if (r % 2 == 1) std::reverse(row.begin(), row.end());
    for (const Pose& pose : row) {
      b.Sample(pose, PoseToDirections(pose), "sample " + PoseText(pose), paths);
    }
  }
}

void ExpandSampleFixed(const v1::SampleFixed& fixed, Builder& b, ProblemSink& sink) {
  for (int i = 0; i < fixed.targets_size() && !b.full(); ++i) {
    const v1::DirectionTarget& t = fixed.targets(i);
    const Result<Pose> pose = SolveTargetPose(t);
    if (!pose.ok()) {  // CheckPlanFields reports these; keep the expansion total anyway
      sink.AddOnce("sampleFixed.targets[" + std::to_string(i) + "]", pose.status().message());
      continue;
    }
    std::string what =
        "target " + std::to_string(i + 1) + " of " + std::to_string(fixed.targets_size());
    if (!t.label().empty()) what += " (" + t.label() + ")";
    const Directions target = TargetDirections(t);
    const bool isotropic_form = !t.has_phi_i() && !t.has_phi_o();
    b.RelocateLampAndDetector(*pose, target, what, isotropic_form);
    b.Sample(*pose, target, "sample " + what, {});
  }
}

// `continued`: the rig is where b.model() says (ExpandPosesFrom), so the first pose relocates the
// detector or turns the dial only when it differs.
void ExpandPoseList(const v1::PoseList& list, const RigDescription& rig, Builder& b,
                    bool continued = false) {
  bool dial_in_use = false;
  if (!rig.has_gamma_axis) {
    for (const v1::PoseEntry& e : list.poses()) dial_in_use |= e.gamma() != 0;
    dial_in_use |= continued && b.model().gamma != 0;
  }
  bool first = !continued;
  for (int i = 0; i < list.poses_size() && !b.full(); ++i) {
    const v1::PoseEntry& e = list.poses(i);
    const Pose pose{e.alpha(), e.beta(), e.gamma(), e.delta()};
    if (dial_in_use && (first || pose.gamma != b.model().gamma)) b.DialTo(pose.gamma);
    if (first || pose.delta != b.model().delta) b.DetectorTo(pose.delta);
    first = false;
    const std::string label = e.label().empty() ? "sample " + PoseText(pose) : e.label();
    b.Sample(pose, PoseToDirections(pose), label, {});  // travel: checked per field
  }
}

// Poses of an adaptive plan in the sample-fixed method's form (sample_fixed_design.h), each a
// target: the RELOCATE_LAMP_AND_DETECTOR prompt giving its θi, θo and φ, then the reading, as
// ExpandSampleFixed does. `labels[i]` names pose i ("seed", "round").
void ExpandFixedPoses(std::span<const Pose> poses, const std::vector<std::string>& labels,
                      Builder& b) {
  for (std::size_t i = 0; i < poses.size() && !b.full(); ++i) {
    const IsoDirection d = adaptive::FixedTarget(poses[i]);
    const Directions target = CanonicalDirections(d);
    const std::string what =
        labels[i] + " pose " + std::to_string(i + 1) + " of " + std::to_string(poses.size());
    b.RelocateLampAndDetector(poses[i], target, what, /*isotropic_form=*/true);
    b.Sample(poses[i], target,
             "sample " + labels[i] + " θi " + Deg(d.theta_i) + " θo " + Deg(d.theta_o) + " φ " +
                 Deg(d.phi),
             {});
  }
}

void ExpandFixedSeed(const adaptive::AdaptiveSpec& spec, Builder& b) {
  const adaptive::SeedGroup seed = adaptive::FixedSeedDesign(spec);
  std::vector<std::string> labels;
  for (std::size_t i = 0; i < seed.poses.size(); ++i) {
    labels.push_back(static_cast<int>(i) < seed.retro_poses ? "seed retro-reflection" : "seed");
  }
  ExpandFixedPoses(seed.poses, labels, b);
}

// The seed design of an adaptive plan, as the pose list it is (seed_design.h), or as targets in
// the sample-fixed form; the rounds come later, chosen from the readings.
void ExpandAdaptiveSeed(const v1::Adaptive& adaptive, const RigDescription& rig, Builder& b) {
  const adaptive::AdaptiveSpec spec = adaptive::ResolveAdaptive(adaptive);
  if (spec.sample_fixed) return ExpandFixedSeed(spec, b);
  v1::PoseList list;
  for (const adaptive::SeedGroup& group : adaptive::MakeSeedDesign(spec, rig)) {
    for (std::size_t i = 0; i < group.poses.size(); ++i) {
      const Pose& p = group.poses[i];
      v1::PoseEntry* e = list.add_poses();
      e->set_alpha(p.alpha);
      e->set_beta(p.beta);
      e->set_gamma(p.gamma);
      e->set_delta(p.delta);
      const bool retro = static_cast<int>(i) < group.retro_poses;
      e->set_label((retro ? "seed retro-reflection " : "seed ") + PoseText(p));
    }
  }
  ExpandPoseList(list, rig, b);
}

v1::PoseList PoseListOf(std::span<const Pose> poses) {
  v1::PoseList list;
  for (const Pose& p : poses) {
    v1::PoseEntry* e = list.add_poses();
    e->set_alpha(p.alpha);
    e->set_beta(p.beta);
    e->set_gamma(p.gamma);
    e->set_delta(p.delta);
  }
  return list;
}

}  // namespace

std::vector<Step> ExpandCheckedPlan(const v1::Plan& plan, const RigDescription& rig,
                                    ProblemSink& sink) {
  Builder b(plan, rig, sink);
  switch (plan.method_case()) {
    case v1::Plan::kSampleRotation:
      ExpandSampleRotation(plan.sample_rotation(), rig, b, sink);
      break;
    case v1::Plan::kSampleFixed:
      ExpandSampleFixed(plan.sample_fixed(), b, sink);
      break;
    case v1::Plan::kPoseList:
      ExpandPoseList(plan.pose_list(), rig, b);
      break;
    case v1::Plan::kAdaptive:
      ExpandAdaptiveSeed(plan.adaptive(), rig, b);
      break;
    case v1::Plan::METHOD_NOT_SET:
      break;
  }
  return b.Take();
}

ExpansionStart StartAfter(std::span<const Step> steps, const v1::Plan& plan,
                          const RigDescription& rig) {
  ExpansionStart start;
  StepTimer timer(rig, ResolveSettings(plan).measurement);
  double reference_at = 0;
  for (const Step& step : steps) {
    timer.Advance(step);
    const double delta_before = start.model.delta;
    start.model = ToModelAngles(step.pose, rig.convention);
    if (step.kind == v1::STEP_KIND_REFERENCE) {
      start.have_reference = true;
      start.relocated_since_reference = false;
      start.samples_since_reference = 0;
      reference_at = timer.elapsed_estimate_s();
    } else if (step.kind == v1::STEP_KIND_SAMPLE) {
      ++start.samples_since_reference;
    } else if (step.prompt == v1::PROMPT_KIND_RELOCATE_DETECTOR ||
               step.prompt == v1::PROMPT_KIND_RELOCATE_LAMP_AND_DETECTOR ||
               (step.kind == v1::STEP_KIND_MOVE && start.model.delta != delta_before)) {
      start.relocated_since_reference = true;
    }
  }
  start.seconds_since_reference = timer.elapsed_estimate_s() - reference_at;
  return start;
}

std::vector<Step> ExpandPosesFrom(const v1::Plan& plan, const RigDescription& rig,
                                  const ExpansionStart& start, std::span<const Pose> poses,
                                  int first_index) {
  ProblemSink ignored;  // the caller's poses are within travel (the candidates are)
  Builder b(plan, rig, ignored);
  b.StartFrom(start);
  if (SampleFixedMethod(plan)) {
    ExpandFixedPoses(poses, std::vector<std::string>(poses.size(), "round"), b);
  } else {
    ExpandPoseList(PoseListOf(poses), rig, b, /*continued=*/true);
  }
  std::vector<Step> steps = b.Take();
  for (Step& s : steps) s.index += first_index;
  return steps;
}

}  // namespace brdf::plan
