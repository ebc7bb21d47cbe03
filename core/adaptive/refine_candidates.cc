#include "core/adaptive/refine_candidates.h"

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <tuple>

#include "core/geometry.h"

namespace brdf::adaptive {
namespace {

auto Key(const Pose& p) {
  return std::tie(p.delta, p.gamma, p.alpha, p.beta);
}

bool KeyLess(const Pose& a, const Pose& b) {
  return Key(a) < Key(b);
}

double Round2(double deg) {
  return std::round(deg * 100) / 100;
}

// β into (−180°, 180°].
double WrapBeta(double beta) {
  while (beta > 180) beta -= 360;
  while (beta <= -180) beta += 360;
  return beta;
}

// The 8 neighbours `h` away in α and β of every anchor, α within [0°, 90°], sorted, unique.
std::vector<Pose> Neighbours(const std::vector<Pose>& anchors, double h) {
  std::vector<Pose> out;
  for (const Pose& a : anchors) {
    for (int i = -1; i <= 1; ++i) {
      for (int j = -1; j <= 1; ++j) {
        if (i == 0 && j == 0) continue;
        const double alpha = Round2(a.alpha + i * h);
        if (alpha < 0 || alpha > 90) continue;
        out.push_back({alpha, Round2(WrapBeta(a.beta + j * h)), a.gamma, a.delta});
      }
    }
  }
  std::sort(out.begin(), out.end(), KeyLess);
  out.erase(std::unique(out.begin(), out.end()), out.end());
  return out;
}

struct Scored {
  Pose pose;
  double gain = 0;
};

// The `keep` poses of `poses` with the largest positive gain (ties: the smaller key), skipping
// those in `known` (sorted).
std::vector<Scored> Best(const std::vector<Pose>& poses, const std::vector<Pose>& known,
                         const UncertaintyMap& map, const RoundCost& cost, int keep) {
  std::vector<Scored> scored;
  for (const Pose& p : poses) {
    if (std::binary_search(known.begin(), known.end(), p, KeyLess) || !cost.CanReach(p)) continue;
    const double gain = map.PredictedGain(PoseToDirections(p));
    if (gain > 0) scored.push_back({p, gain});
  }
  const std::size_t n = std::min(scored.size(), static_cast<std::size_t>(std::max(keep, 0)));
  std::partial_sort(scored.begin(), scored.begin() + static_cast<std::ptrdiff_t>(n), scored.end(),
                    [](const Scored& a, const Scored& b) {
                      return a.gain != b.gain ? a.gain > b.gain : KeyLess(a.pose, b.pose);
                    });
  scored.resize(n);
  return scored;
}

}  // namespace

std::vector<Pose> RefinedCandidates(std::span<const ReadingSoFar> readings,
                                    std::span<const Pose> candidates, const UncertaintyMap& map,
                                    const RoundCost& cost, const RefineOptions& options) {
  if (options.levels <= 0 || !(options.step_deg > 0) || cost.sample_fixed()) return {};
  std::vector<Pose> measured;
  for (const ReadingSoFar& r : readings) measured.push_back(r.pose);
  std::vector<Pose> taken(measured);
  std::sort(taken.begin(), taken.end(), KeyLess);
  std::vector<Pose> known(taken);
  known.insert(known.end(), candidates.begin(), candidates.end());
  std::sort(known.begin(), known.end(), KeyLess);
  // Level 1's anchors besides the readings: the coarse candidates not yet measured that gain most.
  std::vector<Pose> coarse(candidates.begin(), candidates.end());
  std::sort(coarse.begin(), coarse.end(), KeyLess);
  coarse.erase(std::unique(coarse.begin(), coarse.end()), coarse.end());
  std::vector<Scored> best = Best(coarse, taken, map, cost, options.keep);
  std::vector<Pose> out;
  double h = options.step_deg;
  for (int level = 1; level <= options.levels && h > 0; ++level) {
    h /= 2;
    std::vector<Pose> anchors(measured);
    for (const Scored& s : best) anchors.push_back(s.pose);
    best = Best(Neighbours(anchors, h), known, map, cost, options.keep);
    for (const Scored& s : best) out.push_back(s.pose);
    for (const Scored& s : best) known.push_back(s.pose);
    std::sort(known.begin(), known.end(), KeyLess);
  }
  std::sort(out.begin(), out.end(), KeyLess);
  return out;
}

}  // namespace brdf::adaptive
