#include "core/adaptive/candidates.h"

#include <cmath>

#include "core/adaptive/seed_design.h"

namespace brdf::adaptive {

std::vector<Pose> CandidatePoses(const AdaptiveSpec& spec, const plan::RigDescription& rig,
                                 double step_deg) {
  std::vector<Pose> out;
  if (!(step_deg > 0)) return out;
  const int alphas = static_cast<int>(std::floor(90 / step_deg + 1e-9)) + 1;
  const int betas = static_cast<int>(std::floor(360 / step_deg + 1e-9));
  for (double gamma : spec.gamma_deg) {
    for (double delta : spec.delta_deg) {
      for (int a = 0; a < alphas; ++a) {
        for (int b = 0; b < betas; ++b) {
          const Pose pose{a * step_deg, 180 - b * step_deg, gamma, delta};
          if (Reachable(pose, spec.region, rig)) out.push_back(pose);
        }
      }
    }
  }
  return out;
}

}  // namespace brdf::adaptive
