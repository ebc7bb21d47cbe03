#include "core/uncertainty/interpolation_calibration.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <string>

namespace brdf::uncertainty {
namespace {

constexpr double kInfinite = std::numeric_limits<double>::infinity();

// The c a pair needs: 0 when the noise covers it, ∞ when s = 0 and it does not. A spread so
// small beside the residual that c would pass kMaxNeededScale is rounding, not a spread (a
// held-out reading on another reading's coordinates, as several γ make in the isotropic
// reduction: one vertex weighs 1 − 1e-16), and counts as s = 0.
double NeededScale(double residual, double spread, double noise, double k) {
  const double half_width = std::abs(residual) / k;
  const double excess = half_width * half_width - noise * noise;
  if (excess <= 0) return 0;
  const double needed = std::sqrt(excess) / spread;
  if (!(spread > 0) || !(needed <= kMaxNeededScale)) return kInfinite;
  return needed;
}

bool Fits(const HeldOutPoint& p, std::size_t bands) {
  return p.residual.size() == bands && p.spread.size() == bands &&
         (p.noise.empty() || p.noise.size() == bands);
}

// The split-conformal rank of `needed` (sorted in place): its ⌈(n + 1) · coverage⌉-th smallest,
// the largest when that passes n; the largest finite one when the rank falls on an infinite need.
double ConformalScale(std::vector<double>& needed, double coverage) {
  std::sort(needed.begin(), needed.end());
  const double rank = std::ceil(coverage * static_cast<double>(needed.size() + 1));
  const std::size_t at =
      std::min(needed.size() - 1, static_cast<std::size_t>(std::max(rank, 1.0)) - 1);
  for (std::size_t i = at + 1; i-- > 0;) {
    if (std::isfinite(needed[i])) return needed[i];
  }
  return 0;
}

}  // namespace

InterpolationCalibration FitInterpolationCalibration(std::span<const HeldOutPoint> points,
                                                     int bands, const CalibrationTarget& target) {
  InterpolationCalibration out;
  const std::size_t nb = bands > 0 ? static_cast<std::size_t>(bands) : 0;
  std::vector<const HeldOutPoint*> usable;
  for (const HeldOutPoint& p : points) {
    if (nb > 0 && Fits(p, nb)) usable.push_back(&p);
  }
  out.held_out = usable.size();
  if (usable.size() < std::max<std::size_t>(1, target.min_points)) {
    out.detail = std::to_string(usable.size()) + " held-out readings predicted, fewer than " +
                 std::to_string(std::max<std::size_t>(1, target.min_points));
    return out;
  }
  const std::size_t groups =
      std::clamp<std::size_t>(static_cast<std::size_t>(std::max(1, target.band_groups)), 1, nb);
  out.scale.assign(nb, 0.0);
  out.band_groups = groups;
  std::vector<double> needed;
  for (std::size_t g = 0; g < groups; ++g) {
    const std::size_t first = BandGroupFirst(g, groups, nb);
    const std::size_t last = BandGroupFirst(g + 1, groups, nb);
    needed.clear();
    for (const HeldOutPoint* p : usable) {
      for (std::size_t b = first; b < last; ++b) {
        const double noise = p->noise.empty() ? 0.0 : p->noise[b];
        needed.push_back(NeededScale(p->residual[b], p->spread[b], noise, target.k));
      }
    }
    const double c = ConformalScale(needed, target.coverage);
    std::fill(out.scale.begin() + static_cast<std::ptrdiff_t>(first),
              out.scale.begin() + static_cast<std::ptrdiff_t>(last), c);
  }
  out.detail = "fitted on " + std::to_string(usable.size()) + " held-out readings, " +
               std::to_string(groups) + " band groups";
  return out;
}

bool ApplyInterpolationCalibration(const InterpolationCalibration& calibration,
                                   std::span<double> spread) {
  if (calibration.scale.empty() || calibration.scale.size() != spread.size()) return false;
  for (std::size_t b = 0; b < spread.size(); ++b) spread[b] *= calibration.scale[b];
  return true;
}

}  // namespace brdf::uncertainty
