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

// One size bin's c per band: per band group the conformal scale of `points`' needs.
std::vector<double> FitScale(std::span<const HeldOutPoint* const> points, std::size_t nb,
                             std::size_t groups, double k, double coverage) {
  std::vector<double> scale(nb, 0.0);
  std::vector<double> needed;
  for (std::size_t g = 0; g < groups; ++g) {
    const std::size_t first = BandGroupFirst(g, groups, nb);
    const std::size_t last = BandGroupFirst(g + 1, groups, nb);
    needed.clear();
    for (const HeldOutPoint* p : points) {
      for (std::size_t b = first; b < last; ++b) {
        const double noise = p->noise.empty() ? 0.0 : p->noise[b];
        needed.push_back(NeededScale(p->residual[b], p->spread[b], noise, k));
      }
    }
    const double c = ConformalScale(needed, coverage);
    std::fill(scale.begin() + static_cast<std::ptrdiff_t>(first),
              scale.begin() + static_cast<std::ptrdiff_t>(last), c);
  }
  return scale;
}

// `usable` sorted by cell size into `bins` bins of equal counts (the last takes the remainder).
// Each bin's c is the pooled c times the ratio of the bin's kSizeBinQuantile need to the pooled
// one: the needs of a bin taken as the pooled ones scaled, so that a bin's few held-out readings
// whose spread explains nothing (needs of 10³–10⁶) cannot set its c alone. Each bin's c is at
// least the previous bin's: a larger cell is never promised a smaller error.
void FitSizeBins(std::vector<const HeldOutPoint*> usable, std::size_t bins, std::size_t nb,
                 std::size_t groups, const CalibrationTarget& target,
                 InterpolationCalibration* out) {
  std::sort(usable.begin(), usable.end(), [](const HeldOutPoint* a, const HeldOutPoint* b) {
    return a->cell_size < b->cell_size;
  });
  const std::size_t per = usable.size() / bins;
  const std::vector<double> pooled = FitScale(usable, nb, groups, target.k, target.coverage);
  const std::vector<double> pooled_q = FitScale(usable, nb, groups, target.k, kSizeBinQuantile);
  std::vector<double> previous;
  for (std::size_t i = 0; i < bins; ++i) {
    const std::size_t end = i + 1 == bins ? usable.size() : (i + 1) * per;
    std::vector<double> scale = FitScale(std::span(usable).subspan(i * per, end - i * per), nb,
                                         groups, target.k, kSizeBinQuantile);
    for (std::size_t b = 0; b < nb; ++b) {
      scale[b] = pooled_q[b] > 0 ? pooled[b] * scale[b] / pooled_q[b] : pooled[b];
    }
    for (std::size_t b = 0; b < previous.size(); ++b) scale[b] = std::max(scale[b], previous[b]);
    previous = scale;
    if (i == 0) {
      out->scale = std::move(scale);
    } else {
      out->larger.push_back({usable[i * per - 1]->cell_size, std::move(scale)});
    }
  }
  out->largest_cell = usable.back()->cell_size;
  out->beyond = target.beyond;
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
  const std::size_t min_points = std::max<std::size_t>(1, target.min_points);
  if (usable.size() < min_points) {
    out.detail = std::to_string(usable.size()) + " held-out readings predicted, fewer than " +
                 std::to_string(min_points);
    return out;
  }
  const std::size_t groups =
      std::clamp<std::size_t>(static_cast<std::size_t>(std::max(1, target.band_groups)), 1, nb);
  out.band_groups = groups;
  const std::size_t bins = std::clamp<std::size_t>(
      static_cast<std::size_t>(std::max(1, target.size_bins)), 1, usable.size() / min_points);
  if (target.size_bins > 1) {
    FitSizeBins(usable, bins, nb, groups, target, &out);
  } else {
    out.scale = FitScale(usable, nb, groups, target.k, target.coverage);
  }
  out.detail = "fitted on " + std::to_string(usable.size()) + " held-out readings, " +
               std::to_string(groups) + " band groups";
  if (target.size_bins > 1) {
    out.detail += ", " + std::to_string(bins) + " cell-size bins up to " +
                  std::to_string(out.largest_cell).substr(0, 6);
  }
  return out;
}

bool BeyondCalibration(const InterpolationCalibration& calibration, double cell_size) {
  return calibration.largest_cell > 0 && calibration.beyond == SizeBeyond::kNotEstimated &&
         cell_size > calibration.largest_cell;
}

namespace {

// The row ScaleAt takes `band`'s scale from: the last size bin `cell_size` lies above that has
// the band, else the calibration's own.
const std::vector<double>& ScaleRow(const InterpolationCalibration& calibration, double cell_size,
                                    std::size_t band) {
  const std::vector<double>* scale = &calibration.scale;
  for (const SizeBin& bin : calibration.larger) {
    if (cell_size > bin.above && band < bin.scale.size()) scale = &bin.scale;
  }
  return *scale;
}

// Beyond the largest calibrated cell the scale grows with the cell's size.
bool Stretched(const InterpolationCalibration& calibration, double cell_size) {
  return calibration.largest_cell > 0 && cell_size > calibration.largest_cell;
}

}  // namespace

double ScaleAt(const InterpolationCalibration& calibration, double cell_size, std::size_t band) {
  if (band >= calibration.scale.size() || BeyondCalibration(calibration, cell_size)) {
    return std::numeric_limits<double>::quiet_NaN();
  }
  double c = ScaleRow(calibration, cell_size, band)[band];
  if (Stretched(calibration, cell_size)) c *= cell_size / calibration.largest_cell;
  return c;
}

bool ApplyInterpolationCalibration(const InterpolationCalibration& calibration,
                                   std::span<double> spread, double cell_size) {
  if (calibration.scale.empty() || calibration.scale.size() != spread.size()) return false;
  if (BeyondCalibration(calibration, cell_size)) return false;
  if (calibration.largest_cell <= 0 && calibration.larger.empty()) {
    for (std::size_t b = 0; b < spread.size(); ++b) spread[b] *= calibration.scale[b];
    return true;
  }
  // When every size bin has a scale for each band (as CalibrateInterpolation makes them), ScaleAt's
  // row is the same for every band: found once.
  const bool every_band =
      std::all_of(calibration.larger.begin(), calibration.larger.end(),
                  [&](const SizeBin& bin) { return bin.scale.size() >= spread.size(); });
  if (!every_band) {
    for (std::size_t b = 0; b < spread.size(); ++b) {
      spread[b] *= ScaleAt(calibration, cell_size, b);
    }
    return true;
  }
  const std::vector<double>& scale = ScaleRow(calibration, cell_size, 0);
  const bool stretched = Stretched(calibration, cell_size);
  const double stretch = cell_size / calibration.largest_cell;
  for (std::size_t b = 0; b < spread.size(); ++b) {
    double c = scale[b];
    if (stretched) c *= stretch;
    spread[b] *= c;
  }
  return true;
}

}  // namespace brdf::uncertainty
