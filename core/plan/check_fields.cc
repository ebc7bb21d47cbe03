#include "core/plan/check_fields.h"

#include <algorithm>
#include <cmath>
#include <optional>
#include <string>

#include "core/adaptive/adaptive_spec.h"
#include "core/adaptive/check_seed.h"
#include "core/geometry.h"
#include "core/plan/angle_text.h"
#include "core/plan/plan_settings.h"
#include "core/plan/sample.h"

namespace brdf::plan {
namespace {

std::string Index(const std::string& path, int i) {
  return path + "[" + std::to_string(i) + "]";
}

// Number of values of a sweep start, start + step, … ≤ stop (+1e-9), as geometry.h counts them.
double SweepCount(double start, double stop, double step) {
  return std::floor((stop - start + 1e-9) / step) + 1;
}

// Which axis of a Pose a check is about.
enum class Axis { kAlpha, kBeta, kGamma, kDelta };

const char* AxisName(Axis axis) {
  switch (axis) {
    case Axis::kAlpha:
      return "α";
    case Axis::kBeta:
      return "β";
    case Axis::kGamma:
      return "γ";
    case Axis::kDelta:
      return "δ";
  }
  return "?";
}

// The stage reading of one model angle, through the rig's convention.
double Reading(const RigDescription& rig, Axis axis, double model_deg) {
  Pose model;
  switch (axis) {
    case Axis::kAlpha:
      model.alpha = model_deg;
      return ToReadings(model, rig.convention).alpha;
    case Axis::kBeta:
      model.beta = model_deg;
      return ToReadings(model, rig.convention).beta;
    case Axis::kGamma:
      model.gamma = model_deg;
      return ToReadings(model, rig.convention).gamma;
    case Axis::kDelta:
      model.delta = model_deg;
      return ToReadings(model, rig.convention).delta;
  }
  return model_deg;
}

const AxisTravel& Travel(const RigDescription& rig, Axis axis) {
  switch (axis) {
    case Axis::kAlpha:
      return rig.alpha;
    case Axis::kBeta:
      return rig.beta;
    case Axis::kGamma:
      return rig.gamma;
    case Axis::kDelta:
      return rig.delta;
  }
  return rig.alpha;
}

class FieldChecker {
 public:
  FieldChecker(const RigDescription& rig, ProblemSink& sink) : rig_(rig), sink_(sink) {}

  // A value that must be present (an `optional` field without a default). False if missing.
  bool Required(const std::string& path, bool present, const std::string& what) {
    if (present) return true;
    sink_.Add(path, "missing; give " + what);
    return false;
  }

  bool Finite(const std::string& path, double v) {
    if (std::isfinite(v)) return true;
    sink_.Add(path, "is " + Num(v) + "; give a finite number");
    return false;
  }

  // Finite and in [lo, hi].
  bool InRange(const std::string& path, double v, double lo, double hi, const std::string& unit,
               const std::string& what) {
    if (!Finite(path, v)) return false;
    if (v >= lo && v <= hi) return true;
    sink_.Add(path, Num(v) + unit + " is outside [" + Num(lo) + unit + ", " + Num(hi) + unit +
                        "]; give " + what);
    return false;
  }

  // A model angle within the axis' travel (stage readings). Only call with finite values.
  bool WithinTravel(const std::string& path, Axis axis, double model_deg) {
    const AxisTravel& travel = Travel(rig_, axis);
    const double reading = Reading(rig_, axis, model_deg);
    if (travel.Contains(reading)) return true;
    std::string where = std::string(AxisName(axis)) + " = " + Deg(model_deg);
    if (reading != model_deg) where += " (stage reading " + Deg(reading) + ")";
    sink_.Add(path, where + " is beyond the " + AxisName(axis) + " axis' travel [" +
                        Deg(travel.min_deg) + ", " + Deg(travel.max_deg) +
                        "]; change the plan or the rig's travel limits");
    return false;
  }

  // An angle sweep with defaults; returns the number of values, or nullopt after a problem.
  // `lo`/`hi` bound the model angle (geometry), `axis` gives the travel limits.
  std::optional<double> Sweep(const std::string& path, const v1::AngleRange& range,
                              double default_start, double default_stop, double default_step,
                              double lo, double hi, Axis axis) {
    const double start = range.has_start() ? range.start() : default_start;
    const double stop = range.has_stop() ? range.stop() : default_stop;
    const double step = range.has_step() ? range.step() : default_step;
    const std::string name = AxisName(axis);
    bool ok = true;
    ok &= InRange(path + ".start", start, lo, hi, "°", "a " + name + " in that range");
    ok &= InRange(path + ".stop", stop, lo, hi, "°", "a " + name + " in that range");
    if (Finite(path + ".step", step) && step <= 0) {
      sink_.Add(path + ".step", "step must be > 0 (got " + Num(step) + "); give the spacing of " +
                                    name + " values in degrees");
      ok = false;
    } else if (!std::isfinite(step)) {
      ok = false;
    }
    if (!ok) return std::nullopt;
    if (stop < start) {
      sink_.Add(path + ".stop",
                "stop " + Deg(stop) + " is below start " + Deg(start) + "; give stop ≥ start");
      return std::nullopt;
    }
    const double count = SweepCount(start, stop, step);
    if (count > kMaxSweepValues) {
      sink_.Add(path + ".step", "step " + Deg(step) + " gives " + Num(count) + " values of " +
                                    name + " (more than " + std::to_string(kMaxSweepValues) +
                                    "); give a coarser step");
      return std::nullopt;
    }
    const double last = start + (count - 1) * step;
    ok &= WithinTravel(path + ".start", axis, start);
    ok &= WithinTravel(path + ".stop", axis, last);
    if (!ok) return std::nullopt;
    return count;
  }

  // Dial positions γ: finite, each once, within the travel of a motorized γ axis.
  bool DialPositions(const std::string& base,
                     const google::protobuf::RepeatedField<double>& gamma) {
    bool ok = true;
    for (int i = 0; i < gamma.size(); ++i) {
      const std::string path = Index(base, i);
      if (!Finite(path, gamma[i])) {
        ok = false;
        continue;
      }
      for (int j = 0; j < i; ++j) {
        if (gamma[j] == gamma[i]) {
          sink_.Add(path, "γ = " + Deg(gamma[i]) + " repeats " + Index("gamma", j) +
                              "; give each dial position once");
          ok = false;
          break;
        }
      }
      if (rig_.has_gamma_axis) ok &= WithinTravel(path, Axis::kGamma, gamma[i]);
    }
    return ok;
  }

  void SampleRotation(const v1::SampleRotation& r) {
    const GridSpec defaults;
    const std::string base = "sampleRotation";
    const auto n_delta =
        Sweep(base + ".delta", r.delta(), defaults.delta_start_deg, defaults.delta_stop_deg,
              defaults.delta_step_deg, 0, 180, Axis::kDelta);
    const auto n_alpha =
        Sweep(base + ".alpha", r.alpha(), defaults.alpha_start_deg, defaults.alpha_stop_deg,
              defaults.alpha_step_deg, -90, 90, Axis::kAlpha);
    std::optional<double> n_beta;
    const double beta_step = r.beta().has_step() ? r.beta().step() : defaults.beta_step_deg;
    if (Finite(base + ".beta.step", beta_step)) {
      if (beta_step <= 0 || beta_step > 360) {
        sink_.Add(base + ".beta.step", "step must be in (0°, 360°] (got " + Num(beta_step) +
                                           "); give the spacing of β values in degrees");
      } else if (360.0 / beta_step > kMaxSweepValues) {
        sink_.Add(base + ".beta.step", "step " + Deg(beta_step) + " gives more than " +
                                           std::to_string(kMaxSweepValues) +
                                           " β values; give a coarser step");
      } else {
        n_beta = std::floor(360.0 / beta_step) + 1;
      }
    }
    const double theta_max =
        r.beta().has_theta_max_deg() ? r.beta().theta_max_deg() : defaults.theta_max_deg;
    bool theta_ok = Finite(base + ".beta.thetaMaxDeg", theta_max);
    if (theta_ok && (theta_max <= 0 || theta_max > 90)) {
      sink_.Add(base + ".beta.thetaMaxDeg",
                Num(theta_max) +
                    "° is outside (0°, 90°]; give the largest polar angle allowed "
                    "for lamp and detector, e.g. 89.999");
      theta_ok = false;
    }
    const bool gamma_ok = DialPositions(base + ".gamma", r.gamma());
    if (n_delta && n_alpha && n_beta && theta_ok && gamma_ok) {
      const double n_gamma = r.gamma_size() > 0 ? r.gamma_size() : 1;
      const double candidates = *n_delta * *n_alpha * *n_beta * n_gamma;
      if (candidates > kMaxGridCandidates) {
        sink_.Add("", "the sample-rotation grid spans " + Num(candidates) +
                          " δ × α × β × γ combinations (more than " + Num(kMaxGridCandidates) +
                          "), far beyond the " + std::to_string(kMaxSteps) +
                          "-step cap; use coarser steps or narrower ranges");
      }
    }
  }

  void Azimuths(const std::string& p, const v1::DirectionTarget& t) {
    const bool four = t.has_phi_i() || t.has_phi_o();
    if (t.has_phi() && four) {
      sink_.Add(p + ".phi",
                "give either phi (isotropic form) or phiI and phiO (four-angle "
                "form), not both");
      return;
    }
    if (!four) {
      if (Required(p + ".phi", t.has_phi(),
                   "the relative azimuth φ in degrees [0, 180] (or phiI and phiO)")) {
        InRange(p + ".phi", t.phi(), 0, 180, "°", "a relative azimuth φ = |φo − φi| in [0°, 180°]");
      }
      return;
    }
    if (Required(p + ".phiI", t.has_phi_i(), "the lamp's azimuth φi in degrees (-180, 180]")) {
      InRange(p + ".phiI", t.phi_i(), -180, 180, "°", "an azimuth in (-180°, 180°]");
    }
    if (Required(p + ".phiO", t.has_phi_o(), "the detector's azimuth φo in degrees (-180, 180]")) {
      InRange(p + ".phiO", t.phi_o(), -180, 180, "°", "an azimuth in (-180°, 180°]");
    }
  }

  void SampleFixed(const v1::SampleFixed& f) {
    const std::string base = "sampleFixed.targets";
    if (f.targets_size() == 0) {
      sink_.Add(base, "no targets; give at least one direction to measure");
      return;
    }
    if (f.targets_size() > kMaxSteps / 2) {
      sink_.Add(base, std::to_string(f.targets_size()) + " targets need more than the " +
                          std::to_string(kMaxSteps) + "-step cap; split the plan");
      return;
    }
    for (int i = 0; i < f.targets_size(); ++i) {
      const v1::DirectionTarget& t = f.targets(i);
      const std::string p = Index(base, i);
      ProblemSink local;
      FieldChecker inner(rig_, local);
      if (inner.Required(p + ".thetaI", t.has_theta_i(),
                         "the lamp's polar angle θi in degrees [0, 90]")) {
        inner.InRange(p + ".thetaI", t.theta_i(), 0, 90, "°",
                      "a polar angle θi in [0°, 90°] (the lamp above the surface)");
      }
      if (inner.Required(p + ".thetaO", t.has_theta_o(),
                         "the detector's polar angle θo in degrees [0, 90]")) {
        inner.InRange(p + ".thetaO", t.theta_o(), 0, 90, "°",
                      "a polar angle θo in [0°, 90°] (the detector above the surface)");
      }
      inner.Azimuths(p, t);
      if (local.empty()) {
        const Result<Pose> pose = SolveTargetPose(t);
        if (!pose.ok()) {
          sink_.Add(p, "unreachable: " + pose.status().message());
        }
      }
      for (Problem& problem : local.Take()) sink_.Add(problem.field_path, problem.message);
    }
  }

  void PoseList(const v1::PoseList& list) {
    const std::string base = "poseList.poses";
    if (list.poses_size() == 0) {
      sink_.Add(base, "no poses; give at least one");
      return;
    }
    if (list.poses_size() > kMaxSteps / 2) {
      sink_.Add(base, std::to_string(list.poses_size()) + " poses need more than the " +
                          std::to_string(kMaxSteps) + "-step cap; split the plan");
      return;
    }
    for (int i = 0; i < list.poses_size(); ++i) {
      const v1::PoseEntry& e = list.poses(i);
      const std::string p = Index(base, i);
      bool ok = true;
      if (Required(p + ".alpha", e.has_alpha(), "the tilt α in degrees") &&
          InRange(p + ".alpha", e.alpha(), -90, 90, "°", "a tilt α in [-90°, 90°]")) {
        ok &= WithinTravel(p + ".alpha", Axis::kAlpha, e.alpha());
      } else {
        ok = false;
      }
      if (Required(p + ".beta", e.has_beta(), "the turn β in degrees") &&
          Finite(p + ".beta", e.beta())) {
        ok &= WithinTravel(p + ".beta", Axis::kBeta, e.beta());
      } else {
        ok = false;
      }
      if (e.has_gamma() && !Finite(p + ".gamma", e.gamma())) {
        ok = false;
      } else if (rig_.has_gamma_axis) {
        ok &= WithinTravel(p + ".gamma", Axis::kGamma, e.gamma());
      }
      if (Required(p + ".delta", e.has_delta(), "the lamp–sample–detector angle δ in degrees") &&
          InRange(p + ".delta", e.delta(), 0, 180, "°", "a δ in [0°, 180°]")) {
        ok &= WithinTravel(p + ".delta", Axis::kDelta, e.delta());
      } else {
        ok = false;
      }
      if (!ok) continue;
      const Directions d = PoseToDirections(Pose{e.alpha(), e.beta(), e.gamma(), e.delta()});
      if (!IsValid(d, 90)) {
        sink_.Add(p, "this pose puts the " + std::string(d.theta_i > 90 ? "lamp" : "detector") +
                         " below the sample surface (θi = " + Deg(d.theta_i) +
                         ", θo = " + Deg(d.theta_o) + "); change α, β or δ");
      }
    }
  }

  // An adaptive plan's fields (plan.proto: Adaptive); true when all are usable for the seed.
  bool Adaptive(const v1::Adaptive& a, bool anisotropic) {
    const std::string base = "adaptive";
    bool ok = AdaptiveTarget(base + ".target", a);
    ok &= AdaptiveBudget(base + ".budget", a.budget());
    ok &= AdaptiveRegion(base + ".region", a.region());
    ok &= AdaptiveSizes(base, a);
    if (a.has_sample_fixed()) return AdaptiveSampleFixed(base, a, anisotropic) && ok;
    const GridSpec paper;
    const std::optional<double> n_delta =
        Sweep(base + ".delta", a.delta(), paper.delta_start_deg, paper.delta_stop_deg,
              paper.delta_step_deg, 0, 180, Axis::kDelta);
    ok &= n_delta.has_value();
    ok &= DialPositions(base + ".gamma", a.gamma());
    const double settings = n_delta.value_or(0) * std::max(a.gamma_size(), 1);
    if (settings > adaptive::kMaxSeedSettings) {
      sink_.Add(base + ".delta", Num(settings) +
                                     " detector and dial settings (δ × γ) is more than " +
                                     std::to_string(adaptive::kMaxSeedSettings) +
                                     "; give a coarser δ step or fewer dial positions");
      ok = false;
    }
    const double per_delta = a.seed().readings_per_delta() != 0
                                 ? a.seed().readings_per_delta()
                                 : adaptive::kDefaultReadingsPerDelta;
    if (ok && settings * per_delta > adaptive::kMaxSeedReadings) {
      sink_.Add(base + ".seed.readingsPerDelta",
                Num(settings * per_delta) + " seed readings (" + Num(per_delta) + " at each of " +
                    Num(settings) + " settings) is more than " +
                    std::to_string(adaptive::kMaxSeedReadings) +
                    "; give fewer per δ or fewer detector positions");
      ok = false;
    }
    if (a.seed().readings_per_delta() > 500) {
      sink_.Add(base + ".seed.readingsPerDelta",
                std::to_string(a.seed().readings_per_delta()) + " is more than 500; give 1 … 500");
      ok = false;
    }
    if (a.seed().delta_every() > 100) {
      sink_.Add(base + ".seed.deltaEvery", std::to_string(a.seed().delta_every()) +
                                               " is more than 100; give 1 … 100 (1: every δ)");
      ok = false;
    }
    return ok;
  }

  // The sizes both forms share: the retro-reflection scan and the round.
  bool AdaptiveSizes(const std::string& base, const v1::Adaptive& a) {
    bool ok = true;
    const v1::AdaptiveSeed& seed = a.seed();
    if (seed.has_retro_readings() && seed.retro_readings() > 100) {
      sink_.Add(base + ".seed.retroReadings", std::to_string(seed.retro_readings()) +
                                                  " is more than 100; give 0 … 100 (0: no scan)");
      ok = false;
    }
    if (a.round_readings() > 1000) {
      sink_.Add(base + ".roundReadings",
                std::to_string(a.round_readings()) + " is more than 1000; give 1 … 1000");
      ok = false;
    }
    return ok;
  }

  // The sample-fixed form (plan.proto: AdaptiveSampleFixed): lamp and detector set by hand at
  // each pose's directions, so the rig's detector positions and dial do not apply.
  bool AdaptiveSampleFixed(const std::string& base, const v1::Adaptive& a, bool anisotropic) {
    const std::string why =
        " do not apply to the sample-fixed form (sampleFixed: lamp and detector are placed by "
        "hand at each pose's directions); ";
    bool ok = true;
    if (a.has_delta()) {
      sink_.Add(base + ".delta", "detector positions" + why + "leave delta out");
      ok = false;
    }
    if (a.gamma_size() > 0) {
      sink_.Add(base + ".gamma", "dial positions" + why +
                                     "leave gamma out (the sample-fixed form is isotropic only)");
      ok = false;
    }
    if (a.seed().readings_per_delta() != 0) {
      sink_.Add(base + ".seed.readingsPerDelta",
                "readings per detector position" + why +
                    "give the seed's size as sampleFixed.seedReadings");
      ok = false;
    }
    if (a.seed().delta_every() != 0) {
      sink_.Add(base + ".seed.deltaEvery", "a seed's detector positions" + why + "leave it out");
      ok = false;
    }
    if (anisotropic) {
      sink_.Add(base + ".sampleFixed",
                "the sample-fixed form is for isotropic samples only (it sets θi, θo and the "
                "relative azimuth φ); set anisotropic to false, or use the sample-rotation "
                "form with gamma");
      ok = false;
    }
    const std::uint32_t seed = a.sample_fixed().seed_readings();
    if (seed > 500) {
      sink_.Add(base + ".sampleFixed.seedReadings",
                std::to_string(seed) + " is more than 500; give 1 … 500 (0: the default, " +
                    std::to_string(adaptive::kDefaultFixedSeedReadings) + ")");
      ok = false;
    }
    return ok;
  }

  bool AdaptiveTarget(const std::string& path, const v1::Adaptive& a) {
    if (!a.has_target()) {
      sink_.Add(path,
                "missing; give expandedUncertainty (k = 2) or expectedError, relative "
                "(e.g. {\"expandedUncertainty\": 0.05} for 5 %)");
      return false;
    }
    const v1::AdaptiveTarget& t = a.target();
    if (t.has_expanded_uncertainty() == t.has_expected_error()) {
      sink_.Add(path, t.has_expected_error()
                          ? "give either expandedUncertainty or expectedError, not both"
                          : "no level; give expandedUncertainty (k = 2) or expectedError, "
                            "relative (e.g. 0.05 for 5 %)");
      return false;
    }
    const bool expanded = t.has_expanded_uncertainty();
    const double level = expanded ? t.expanded_uncertainty() : t.expected_error();
    const std::string field = path + (expanded ? ".expandedUncertainty" : ".expectedError");
    if (!Finite(field, level)) return false;
    if (level > 0 && level <= 1) return true;
    sink_.Add(field, Num(level) + " is outside (0, 1]; give a relative level, e.g. 0.05 for 5 %");
    return false;
  }

  bool AdaptiveBudget(const std::string& path, const v1::AdaptiveBudget& b) {
    const double minutes = b.max_rig_minutes();
    if (!Finite(path + ".maxRigMinutes", minutes)) return false;
    if (minutes < 0) {
      sink_.Add(path + ".maxRigMinutes",
                Num(minutes) + " is negative; give minutes > 0 (0: no limit of its own)");
      return false;
    }
    if (b.max_readings() == 0 && minutes == 0 && b.max_prompts() == 0) {
      sink_.Add(path,
                "no limit; give at least one of maxReadings, maxRigMinutes, maxPrompts "
                "(the session stops at the first reached, or at the target)");
      return false;
    }
    return true;
  }

  // One polar-angle limit pair of the region: min in [0, 90), max in (min, 90).
  bool ThetaLimits(const std::string& path, const char* name, bool has_min, double min,
                   bool has_max, double max) {
    const double lo = has_min ? min : 0;
    const double hi = has_max ? max : adaptive::kDefaultThetaMaxDeg;
    const std::string what = std::string("a polar angle ") + name + " in degrees";
    bool ok = InRange(path + "Min" + "Deg", lo, 0, 90, "°", what + " [0°, 90°)");
    ok &= InRange(path + "Max" + "Deg", hi, 0, 90, "°", what + " (0°, 90°)");
    if (!ok) return false;
    if (hi >= 90 || hi <= lo) {
      sink_.Add(path + "MaxDeg", Deg(hi) + " is not between " + name + " min (" + Deg(lo) +
                                     ") and 90°; give a larger limit below grazing, e.g. 80");
      return false;
    }
    return true;
  }

  bool AdaptiveRegion(const std::string& path, const v1::AdaptiveRegion& r) {
    bool ok = ThetaLimits(path + ".thetaI", "θi", r.has_theta_i_min_deg(), r.theta_i_min_deg(),
                          r.has_theta_i_max_deg(), r.theta_i_max_deg());
    ok &= ThetaLimits(path + ".thetaO", "θo", r.has_theta_o_min_deg(), r.theta_o_min_deg(),
                      r.has_theta_o_max_deg(), r.theta_o_max_deg());
    return ok;
  }

  void Reference(const v1::ReferencePolicy& r) {
    if (Finite("reference.everyMinutes", r.every_minutes()) && r.every_minutes() < 0) {
      sink_.Add("reference.everyMinutes",
                Num(r.every_minutes()) + " is negative; give minutes ≥ 0 (0: off)");
    }
    InRange("reference.pose.alpha", r.pose().alpha(), -90, 90, "°", "a tilt α in [-90°, 90°]");
    if (r.pose().has_beta()) Finite("reference.pose.beta", r.pose().beta());
  }

  void Measurement(const v1::MeasurementSettings& m) {
    if (m.integration_ms() != 0 && (m.integration_ms() < 10 || m.integration_ms() > 6000)) {
      sink_.Add("measurement.integrationMs",
                std::to_string(m.integration_ms()) +
                    " ms is outside the meter's 10 … 6000 ms; give 0 for adaptive integration");
    }
    if (m.averages() > 99) {
      sink_.Add("measurement.averages",
                std::to_string(m.averages()) + " is more than the meter's 99; give 1 … 99");
    }
  }

  void Retry(const v1::RetryPolicy& r) {
    const RetrySettings defaults;
    if (r.max_attempts() > 20) {
      sink_.Add("retry.maxAttempts",
                std::to_string(r.max_attempts()) + " is more than 20; give 1 … 20 (1: no retry)");
    }
    const std::uint32_t backoff = r.has_backoff_ms() ? r.backoff_ms() : defaults.backoff_ms;
    if (backoff > 600000) {
      sink_.Add("retry.backoffMs",
                std::to_string(backoff) + " ms is more than 600000 (10 min); give less");
    }
    if (r.has_backoff_multiplier()) {
      InRange("retry.backoffMultiplier", r.backoff_multiplier(), 1, 10, "",
              "a growth factor in [1, 10]");
    }
    if (r.max_backoff_ms() != 0 && r.max_backoff_ms() < backoff) {
      sink_.Add("retry.maxBackoffMs", std::to_string(r.max_backoff_ms()) +
                                          " ms is below backoffMs (" + std::to_string(backoff) +
                                          " ms); give a cap ≥ the first wait");
    }
  }

 private:
  const RigDescription& rig_;
  ProblemSink& sink_;
};

}  // namespace

Result<Pose> SolveTargetPose(const v1::DirectionTarget& target) {
  const Directions want = TargetDirections(target);
  BRDF_ASSIGN_OR_RETURN(Pose pose, InverseKinematics(ToIsotropic(want)));
  const bool four = target.has_phi_i() || target.has_phi_o();
  if (!four) return pose;
  auto wrap = [](double a) {
    a = std::remainder(a, 360.0);
    return a <= -180 ? a + 360 : a;
  };
  const bool lamp_on_normal = want.theta_i <= kNormalThetaEpsilonDeg;
  const bool detector_on_normal = want.theta_o <= kNormalThetaEpsilonDeg;
  if (lamp_on_normal && detector_on_normal) return pose;
  // Inverse kinematics gives φo − φi in [0°, 180°] (α ≥ 0); the mirror image, φo − φi < 0,
  // is the same pose with α negated (cos θi and cos θo keep their values, n·(L×V) flips sign).
  if (!lamp_on_normal && !detector_on_normal && wrap(want.phi_o - want.phi_i) < 0) {
    pose.alpha = -pose.alpha;
  }
  // γ turns the sample about its normal, shifting both azimuths together: pick the γ that
  // puts the lamp (or, at normal incidence, the detector) at the requested azimuth.
  auto azimuth = [&](const Directions& d) { return lamp_on_normal ? d.phi_o : d.phi_i; };
  const double have = azimuth(PoseToDirections(pose));
  for (double gamma : {wrap(have - azimuth(want)), wrap(azimuth(want) - have)}) {
    Pose candidate = pose;
    candidate.gamma = gamma;
    const Directions got = PoseToDirections(candidate);
    const bool lamp_ok = lamp_on_normal || std::fabs(wrap(got.phi_i - want.phi_i)) < 1e-6;
    const bool detector_ok = detector_on_normal || std::fabs(wrap(got.phi_o - want.phi_o)) < 1e-6;
    if (lamp_ok && detector_ok) return candidate;
  }
  return Internal("inverse kinematics: no dial position γ gives the azimuths φi = " +
                  Deg(want.phi_i) + ", φo = " + Deg(want.phi_o) + "; this is a bug, report it");
}

void CheckPlanFields(const v1::Plan& plan, const RigDescription& rig, ProblemSink& sink) {
  FieldChecker check(rig, sink);
  if (plan.name().size() > kMaxNameLength) {
    sink.Add("name", "is " + std::to_string(plan.name().size()) + " bytes long; give at most " +
                         std::to_string(kMaxNameLength));
  }
  switch (plan.method_case()) {
    case v1::Plan::kSampleRotation:
      check.SampleRotation(plan.sample_rotation());
      break;
    case v1::Plan::kSampleFixed:
      check.SampleFixed(plan.sample_fixed());
      break;
    case v1::Plan::kPoseList:
      check.PoseList(plan.pose_list());
      break;
    case v1::Plan::kAdaptive:
      if (check.Adaptive(plan.adaptive(), plan.anisotropic())) {
        adaptive::CheckSeedDesign(plan.adaptive(), rig, sink);
      }
      break;
    case v1::Plan::METHOD_NOT_SET:
      sink.Add("method",
               "no measurement method; set one of sampleRotation, sampleFixed, poseList, adaptive");
      break;
  }
  check.Reference(plan.reference());
  check.Measurement(plan.measurement());
  check.Retry(plan.retry());
  if (plan.has_sample()) CheckSample(plan.sample(), sink);
}

}  // namespace brdf::plan
