#include "core/export/merl/layout.h"

#include <cmath>
#include <numbers>

namespace brdf::exports {
namespace {

constexpr double kPi = std::numbers::pi;
constexpr double kRadToDeg = 180.0 / kPi;
constexpr double kDegToRad = kPi / 180.0;

struct V3 {
  double x, y, z;
};

V3 Normalize(V3 v) {
  const double len = std::sqrt(v.x * v.x + v.y * v.y + v.z * v.z);
  return {v.x / len, v.y / len, v.z / len};
}

// The reader's rotate_vector: v·cos a + axis·(axis·v)·(1 − cos a) + (axis × v)·sin a.
V3 Rotate(V3 v, V3 axis, double angle) {
  const double c = std::cos(angle), s = std::sin(angle);
  const double dot = axis.x * v.x + axis.y * v.y + axis.z * v.z;
  const V3 cross{axis.y * v.z - axis.z * v.y, axis.z * v.x - axis.x * v.z,
                 axis.x * v.y - axis.y * v.x};
  return {v.x * c + axis.x * dot * (1 - c) + cross.x * s,
          v.y * c + axis.y * dot * (1 - c) + cross.y * s,
          v.z * c + axis.z * dot * (1 - c) + cross.z * s};
}

V3 FromAngles(double theta, double phi) {
  const double s = std::sin(theta);
  return {s * std::cos(phi), s * std::sin(phi), std::cos(theta)};
}

}  // namespace

HalfDiff StdToHalfDiff(double theta_in, double phi_in, double theta_out, double phi_out) {
  const V3 in = Normalize(FromAngles(theta_in, phi_in));
  const V3 out = Normalize(FromAngles(theta_out, phi_out));
  const V3 half = Normalize({(in.x + out.x) / 2, (in.y + out.y) / 2, (in.z + out.z) / 2});
  HalfDiff hd;
  hd.theta_half = std::acos(half.z);
  hd.phi_half = std::atan2(half.y, half.x);
  const V3 temp = Rotate(in, {0, 0, 1}, -hd.phi_half);
  const V3 diff = Rotate(temp, {0, 1, 0}, -hd.theta_half);
  hd.theta_diff = std::acos(diff.z);
  hd.phi_diff = std::atan2(diff.y, diff.x);
  return hd;
}

int MerlThetaHalfIndex(double theta_half) {
  if (theta_half <= 0.0) return 0;
  const double theta_half_deg = theta_half / (kPi / 2.0) * kMerlThetaHalfRes;
  const int i = static_cast<int>(std::sqrt(theta_half_deg * kMerlThetaHalfRes));
  if (i < 0) return 0;
  return i >= kMerlThetaHalfRes ? kMerlThetaHalfRes - 1 : i;
}

int MerlThetaDiffIndex(double theta_diff) {
  const int i = static_cast<int>(theta_diff / (kPi * 0.5) * kMerlThetaDiffRes);
  if (i < 0) return 0;
  return i < kMerlThetaDiffRes - 1 ? i : kMerlThetaDiffRes - 1;
}

int MerlPhiDiffIndex(double phi_diff) {
  if (phi_diff < 0.0) phi_diff += kPi;
  const int i = static_cast<int>(phi_diff / kPi * kMerlPhiDiffRes);
  if (i < 0) return 0;
  return i < kMerlPhiDiffRes - 1 ? i : kMerlPhiDiffRes - 1;
}

MerlCellDirections CellDirections(int theta_half_index, int theta_diff_index, int phi_diff_index) {
  const double u = theta_half_index + 0.5;
  const double theta_half = u * u / kMerlThetaHalfRes * kDegToRad;
  const double theta_diff = (theta_diff_index + 0.5) * kDegToRad;
  const double phi_diff = (phi_diff_index + 0.5) * kDegToRad;
  // The reader's d = Ry(−θh) · Rz(−φh) · ωi, inverted with φh = 0: ωi = Ry(θh) · d; ωo is ωi
  // mirrored about h.
  const V3 d = FromAngles(theta_diff, phi_diff);
  const V3 in = Rotate(d, {0, 1, 0}, theta_half);
  const V3 h{std::sin(theta_half), 0.0, std::cos(theta_half)};
  const double hd = 2 * (h.x * in.x + h.y * in.y + h.z * in.z);
  const V3 out{hd * h.x - in.x, hd * h.y - in.y, hd * h.z - in.z};
  auto theta = [](V3 v) { return std::atan2(std::hypot(v.x, v.y), v.z) * kRadToDeg; };
  auto phi = [](V3 v) { return std::atan2(v.y, v.x) * kRadToDeg; };
  MerlCellDirections cell;
  cell.directions = {theta(in), phi(in), theta(out), phi(out)};
  cell.above = in.z >= 0 && out.z >= 0;
  return cell;
}

}  // namespace brdf::exports
