#include "core/material/builtin_samples.h"

#include <memory>
#include <vector>

#include "core/material/diffuse_lobes.h"
#include "core/material/glossy_lobes.h"

namespace brdf::material {

Material FromAnalytic(const AnalyticBrdfParams& p, std::string name) {
  std::vector<std::shared_ptr<const Lobe>> lobes;
  lobes.push_back(std::make_shared<LambertLobe>(
      SpectralValue::Bump(p.diffuse_base, p.diffuse_amp, p.diffuse_peak_nm, p.diffuse_width_nm)));
  lobes.push_back(std::make_shared<BlinnPhongLobe>(SpectralValue::Constant(p.specular_weight),
                                                   p.exponent_x, p.exponent_y));
  return Material(std::move(name), std::move(lobes));
}

Material PaintMaterial() {
  return FromAnalytic(AnalyticBrdf::PaintLike().params(), "paint-like");
}

Material GlossyMaterial() {
  return FromAnalytic(AnalyticBrdf::Glossy().params(), "glossy");
}

Material BrushedMaterial() {
  return FromAnalytic(AnalyticBrdf::Brushed().params(), "brushed (anisotropic)");
}

}  // namespace brdf::material
