#include "core/geometry.h"

#include <algorithm>
#include <cmath>
#include <map>
#include <numbers>
#include <sstream>
#include <tuple>
#include <utility>

namespace brdf {
namespace {

constexpr double kDegToRad = std::numbers::pi / 180.0;
constexpr double kRadToDeg = 180.0 / std::numbers::pi;
// Grid loops include their stop value when it is on the grid up to this slack (degrees).
constexpr double kGridSlackDeg = 1e-9;

struct Vec3 {
  double x = 0, y = 0, z = 0;
};

double Dot(const Vec3& a, const Vec3& b) {
  return a.x * b.x + a.y * b.y + a.z * b.z;
}
Vec3 Cross(const Vec3& a, const Vec3& b) {
  return {a.y * b.z - a.z * b.y, a.z * b.x - a.x * b.z, a.x * b.y - a.y * b.x};
}
double Norm(const Vec3& a) {
  return std::sqrt(Dot(a, a));
}

std::string Fmt(double v) {
  std::ostringstream s;
  s.precision(10);
  s << v;
  return s.str();
}

std::string IsoText(const IsoDirection& t) {
  return "(θi, θo, φ) = (" + Fmt(t.theta_i) + "°, " + Fmt(t.theta_o) + "°, " + Fmt(t.phi) + "°)";
}

// Azimuth in (−180, 180]: atan2 can return −180 for a −0 second component.
double AzimuthDeg(double y, double x) {
  const double phi = std::atan2(y, x) * kRadToDeg;
  return phi <= -180.0 ? phi + 360.0 : phi;
}

// Wraps an angle into (−180, 180].
double Wrap180(double deg) {
  double w = std::fmod(deg, 360.0);
  if (w <= -180.0) w += 360.0;
  if (w > 180.0) w -= 360.0;
  return w;
}

// Local (θ, φ) of a lab vector d in the frame (t, b, n).
void LocalAngles(const Vec3& d, const Vec3& t, const Vec3& b, const Vec3& n, double& theta,
                 double& phi) {
  const double x = Dot(d, t), y = Dot(d, b), z = Dot(d, n);
  theta = std::atan2(std::hypot(x, y), z) * kRadToDeg;
  phi = AzimuthDeg(y, x);
}

Status CheckAxis(const AxisConvention& a, const char* name) {
  if (a.sign != 1.0 && a.sign != -1.0) {
    return InvalidArgument(std::string("holder convention: axis ") + name + " has sign " +
                           Fmt(a.sign) + "; use +1 (as in geometry.md) or -1 (reversed)");
  }
  if (!std::isfinite(a.zero_deg)) {
    return InvalidArgument(std::string("holder convention: axis ") + name +
                           " has a non-finite zero offset; give the stage reading at which " +
                           name + " = 0, in degrees");
  }
  return Status::Ok();
}

// Values start, start + step, … ≤ stop (+ slack). Computed as start + k·step to avoid drift.
std::vector<double> Steps(double start, double stop, double step) {
  std::vector<double> out;
  for (int k = 0;; ++k) {
    const double v = start + step * k;
    if (v > stop + kGridSlackDeg) break;
    out.push_back(v);
  }
  return out;
}

Status CheckRange(double start, double stop, double step, const char* axis) {
  const std::string a = axis;
  if (!std::isfinite(start) || !std::isfinite(stop) || !std::isfinite(step)) {
    return InvalidArgument("grid spec: " + a + "_start/stop/step_deg must be finite (got " +
                           Fmt(start) + ", " + Fmt(stop) + ", " + Fmt(step) + ")");
  }
  if (step <= 0) {
    return InvalidArgument("grid spec: " + a + "_step_deg is " + Fmt(step) +
                           "; give a positive step in degrees");
  }
  if (start > stop) {
    return InvalidArgument("grid spec: " + a + "_start_deg " + Fmt(start) + " is after " + a +
                           "_stop_deg " + Fmt(stop) + "; swap them");
  }
  // A bound on the loop length keeps a tiny step from expanding into millions of poses.
  if ((stop - start) / step > 100000) {
    return InvalidArgument("grid spec: " + a + "_step_deg " + Fmt(step) +
                           " gives more than 100000 values; use a coarser step");
  }
  return Status::Ok();
}

}  // namespace

Status ValidateConvention(const HolderConvention& c) {
  BRDF_RETURN_IF_ERROR(CheckAxis(c.alpha, "alpha"));
  BRDF_RETURN_IF_ERROR(CheckAxis(c.beta, "beta"));
  BRDF_RETURN_IF_ERROR(CheckAxis(c.gamma, "gamma"));
  BRDF_RETURN_IF_ERROR(CheckAxis(c.delta, "delta"));
  return Status::Ok();
}

Status ValidatePose(const Pose& p) {
  const std::pair<double, const char*> angles[] = {
      {p.alpha, "alpha"}, {p.beta, "beta"}, {p.gamma, "gamma"}, {p.delta, "delta"}};
  for (const auto& [v, name] : angles) {
    if (!std::isfinite(v)) {
      return InvalidArgument(std::string("pose: ") + name + " is " + Fmt(v) +
                             "; every pose angle must be a finite number of degrees");
    }
  }
  return Status::Ok();
}

Pose ToModelAngles(const Pose& r, const HolderConvention& c) {
  return {c.alpha.sign * (r.alpha - c.alpha.zero_deg), c.beta.sign * (r.beta - c.beta.zero_deg),
          c.gamma.sign * (r.gamma - c.gamma.zero_deg), c.delta.sign * (r.delta - c.delta.zero_deg)};
}

Pose ToReadings(const Pose& m, const HolderConvention& c) {
  // sign is ±1, so dividing by it is multiplying by it.
  return {c.alpha.zero_deg + c.alpha.sign * m.alpha, c.beta.zero_deg + c.beta.sign * m.beta,
          c.gamma.zero_deg + c.gamma.sign * m.gamma, c.delta.zero_deg + c.delta.sign * m.delta};
}

Directions PoseToDirections(const Pose& pose, const HolderConvention& convention) {
  const Pose m = ToModelAngles(pose, convention);
  const double ca = std::cos(m.alpha * kDegToRad), sa = std::sin(m.alpha * kDegToRad);
  const double cb = std::cos(m.beta * kDegToRad), sb = std::sin(m.beta * kDegToRad);
  const double cg = std::cos(m.gamma * kDegToRad), sg = std::sin(m.gamma * kDegToRad);
  // Columns of Rz(β)·Ry(−α) applied to the rest frame: x → n, y → t, z → b (γ = 0).
  const Vec3 n{ca * cb, ca * sb, sa};
  const Vec3 t0{-sb, cb, 0};
  const Vec3 b0{-sa * cb, -sa * sb, ca};
  // Rx(γ) turns the rest tangent y to cosγ·y + sinγ·z and the bitangent z to −sinγ·y + cosγ·z.
  const Vec3 t{cg * t0.x + sg * b0.x, cg * t0.y + sg * b0.y, cg * t0.z + sg * b0.z};
  const Vec3 b{-sg * t0.x + cg * b0.x, -sg * t0.y + cg * b0.y, -sg * t0.z + cg * b0.z};
  const Vec3 lamp{1, 0, 0};
  const Vec3 detector{std::cos(m.delta * kDegToRad), std::sin(m.delta * kDegToRad), 0};
  Directions d;
  LocalAngles(lamp, t, b, n, d.theta_i, d.phi_i);
  LocalAngles(detector, t, b, n, d.theta_o, d.phi_o);
  return d;
}

IsoDirection ToIsotropic(const Directions& d) {
  IsoDirection iso{d.theta_i, d.theta_o, 0.0};
  if (std::fabs(d.theta_i) < kNormalThetaEpsilonDeg ||
      std::fabs(d.theta_o) < kNormalThetaEpsilonDeg)
    return iso;
  double phi = std::fmod(std::fabs(d.phi_o - d.phi_i), 360.0);
  if (phi > 180.0) phi = 360.0 - phi;
  iso.phi = phi;
  return iso;
}

Directions CanonicalDirections(const IsoDirection& iso) {
  return {iso.theta_i, 0.0, iso.theta_o, iso.phi};
}

bool IsValid(const Directions& d, double theta_max_deg) {
  if (!std::isfinite(d.theta_i) || !std::isfinite(d.theta_o) || !std::isfinite(d.phi_i) ||
      !std::isfinite(d.phi_o))
    return false;
  return d.theta_i >= 0 && d.theta_o >= 0 && d.theta_i <= theta_max_deg &&
         d.theta_o <= theta_max_deg;
}

Status ValidateIsoDirection(const IsoDirection& iso) {
  const std::tuple<double, const char*, double, double> fields[] = {
      {iso.theta_i, "theta_i", 0.0, 90.0},
      {iso.theta_o, "theta_o", 0.0, 90.0},
      {iso.phi, "phi", 0.0, 180.0}};
  for (const auto& [v, name, lo, hi] : fields) {
    if (!std::isfinite(v) || v < lo || v > hi) {
      return InvalidArgument(std::string("isotropic direction: ") + name + " = " + Fmt(v) +
                             "° is outside [" + Fmt(lo) + "°, " + Fmt(hi) +
                             "°]; θ is measured from the sample normal, φ = |φo − φi| folded");
    }
  }
  return Status::Ok();
}

Result<Pose> InverseKinematics(const IsoDirection& target, const HolderConvention& convention,
                               const PoseLimits& limits) {
  BRDF_RETURN_IF_ERROR(ValidateIsoDirection(target));
  BRDF_RETURN_IF_ERROR(ValidateConvention(convention));
  const double ti = target.theta_i * kDegToRad, to = target.theta_o * kDegToRad;
  const double ph = target.phi * kDegToRad;
  // Lamp and detector in a sample frame with φi = 0.
  const Vec3 wi{std::sin(ti), 0, std::cos(ti)};
  const Vec3 wo{std::sin(to) * std::cos(ph), std::sin(to) * std::sin(ph), std::cos(to)};
  const Vec3 cross = Cross(wi, wo);
  const double sin_delta = Norm(cross);
  const double cos_delta = Dot(wi, wo);
  Pose model;
  if (sin_delta < 1e-15) {
    if (cos_delta > 0) {  // δ = 0: lamp and detector coincide.
      model.alpha = 0;
      model.beta = target.theta_i;
      model.delta = 0;
    } else {  // δ = 180°: both grazing, opposite.
      model.alpha = 0;
      model.beta = 90;
      model.delta = 180;
    }
  } else {
    model.delta = std::atan2(sin_delta, cos_delta) * kRadToDeg;
    // c = cos α. c·cos β = n·L = cos θi; c·sin β = n·ŷ with ŷ = ẑ × L and ẑ = (wi × wo)/sin δ the
    // lab's vertical seen from the sample: (cross × wi)_z / sin δ = (cos θo − cos θi cos δ)/sin δ.
    const double c_cos_beta = wi.z;
    const double c_sin_beta = Cross(cross, wi).z / sin_delta;
    const double c = std::hypot(c_cos_beta, c_sin_beta);
    if (c > 1.0 + 1e-12) {
      return InvalidArgument("inverse kinematics: no holder tilt alpha reaches " + IsoText(target) +
                             ": cos(alpha) would be " + Fmt(c) + " > 1; check the target angles");
    }
    // sin α = n·ẑ = (wi × wo)_z / sin δ. atan2 keeps α accurate near 0, where acos(c) would lose
    // half the digits.
    const double sin_alpha = cross.z / sin_delta;
    model.alpha = std::atan2(sin_alpha, std::min(c, 1.0)) * kRadToDeg;
    model.beta = c > 0 ? std::atan2(c_sin_beta, c_cos_beta) * kRadToDeg : 0.0;
  }
  model.beta = Wrap180(model.beta);
  model.gamma = 0;
  if (model.alpha < limits.alpha_min_deg - 1e-9 || model.alpha > limits.alpha_max_deg + 1e-9) {
    return InvalidArgument(
        "inverse kinematics: " + IsoText(target) + " needs alpha = " + Fmt(model.alpha) +
        "°, outside the holder's range [" + Fmt(limits.alpha_min_deg) + "°, " +
        Fmt(limits.alpha_max_deg) + "°]; drop this point or widen the alpha limits");
  }
  if (model.delta < limits.delta_min_deg - 1e-9 || model.delta > limits.delta_max_deg + 1e-9) {
    return InvalidArgument(
        "inverse kinematics: " + IsoText(target) + " needs delta = " + Fmt(model.delta) +
        "°, outside the detector's range [" + Fmt(limits.delta_min_deg) + "°, " +
        Fmt(limits.delta_max_deg) + "°]; drop this point or widen the delta limits");
  }
  return ToReadings(model, convention);
}

Status ValidateGridSpec(const GridSpec& s) {
  BRDF_RETURN_IF_ERROR(CheckRange(s.delta_start_deg, s.delta_stop_deg, s.delta_step_deg, "delta"));
  BRDF_RETURN_IF_ERROR(CheckRange(s.alpha_start_deg, s.alpha_stop_deg, s.alpha_step_deg, "alpha"));
  if (!std::isfinite(s.beta_step_deg) || s.beta_step_deg <= 0 || s.beta_step_deg > 360) {
    return InvalidArgument("grid spec: beta_step_deg is " + Fmt(s.beta_step_deg) +
                           "; give a step in (0°, 360°]");
  }
  if (360.0 / s.beta_step_deg > 100000) {
    return InvalidArgument("grid spec: beta_step_deg " + Fmt(s.beta_step_deg) +
                           " gives more than 100000 values; use a coarser step");
  }
  if (!std::isfinite(s.theta_max_deg) || s.theta_max_deg <= 0 || s.theta_max_deg > 90) {
    return InvalidArgument("grid spec: theta_max_deg is " + Fmt(s.theta_max_deg) +
                           "; give a margin angle in (0°, 90°], e.g. 89.999");
  }
  if (s.gamma_deg.empty()) {
    return InvalidArgument(
        "grid spec: gamma_deg is empty; give at least one dial position ({0} "
        "for an isotropic sample)");
  }
  for (double g : s.gamma_deg) {
    if (!std::isfinite(g)) {
      return InvalidArgument("grid spec: gamma_deg holds " + Fmt(g) +
                             "; every dial position must be finite");
    }
  }
  return Status::Ok();
}

Result<std::vector<Pose>> ExpandSampleRotationGrid(const GridSpec& spec,
                                                   const HolderConvention& convention) {
  BRDF_RETURN_IF_ERROR(ValidateGridSpec(spec));
  BRDF_RETURN_IF_ERROR(ValidateConvention(convention));
  // β: the multiples k·step in (−180, 180].
  std::vector<double> betas;
  const int k_min = static_cast<int>(std::floor(-180.0 / spec.beta_step_deg)) - 1;
  for (int k = k_min;; ++k) {
    const double b = spec.beta_step_deg * k;
    if (b > 180.0 + kGridSlackDeg) break;
    if (b > -180.0 + kGridSlackDeg) betas.push_back(b);
  }
  const std::vector<double> deltas =
      Steps(spec.delta_start_deg, spec.delta_stop_deg, spec.delta_step_deg);
  const std::vector<double> alphas =
      Steps(spec.alpha_start_deg, spec.alpha_stop_deg, spec.alpha_step_deg);
  std::vector<Pose> poses;
  for (double gamma : spec.gamma_deg) {
    for (double delta : deltas) {
      for (double alpha : alphas) {
        for (double beta : betas) {
          const Pose model{alpha, beta, gamma, delta};
          if (IsValid(PoseToDirections(model), spec.theta_max_deg)) {
            poses.push_back(ToReadings(model, convention));
          }
        }
      }
    }
  }
  if (poses.empty()) {
    // E.g. α = 0, β every 90° and δ ≥ 90° leave the detector at grazing or below at every pose:
    // a grid that would measure nothing is a mistake in the spec, not an empty answer.
    return InvalidArgument(
        "grid spec: no pose of the grid keeps both lamp and detector above the surface (θ < " +
        Fmt(spec.theta_max_deg) + "°) with δ in [" + Fmt(spec.delta_start_deg) + "°, " +
        Fmt(spec.delta_stop_deg) + "°] and α in [" + Fmt(spec.alpha_start_deg) + "°, " +
        Fmt(spec.alpha_stop_deg) + "°]; lower δ (the lamp–detector angle) or widen the α range");
  }
  return poses;
}

std::vector<IsoDirection> DistinctIsoPoints(std::span<const IsoDirection> points,
                                            double tolerance_deg) {
  std::vector<IsoDirection> kept;
  // Kept points by θi, so that each new point is compared with its θi neighbours only.
  std::multimap<double, std::size_t> by_theta_i;
  for (const IsoDirection& p : points) {
    bool seen = false;
    for (auto it = by_theta_i.lower_bound(p.theta_i - tolerance_deg);
         it != by_theta_i.end() && it->first <= p.theta_i + tolerance_deg; ++it) {
      const IsoDirection& q = kept[it->second];
      if (std::fabs(q.theta_o - p.theta_o) <= tolerance_deg &&
          std::fabs(q.phi - p.phi) <= tolerance_deg) {
        seen = true;
        break;
      }
    }
    if (!seen) {
      by_theta_i.emplace(p.theta_i, kept.size());
      kept.push_back(p);
    }
  }
  return kept;
}

std::size_t CountDistinctIsoPoints(std::span<const IsoDirection> points, double tolerance_deg) {
  return DistinctIsoPoints(points, tolerance_deg).size();
}

}  // namespace brdf
