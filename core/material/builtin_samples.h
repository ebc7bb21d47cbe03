// brdf-sim's compiled-in samples (core/analytic_brdf.h: the paint, the glossy sample and the
// brushed one) as materials: a Lambert lobe whose albedo is the paint's bump spectrum, under a
// Blinn–Phong lobe. They evaluate to exactly AnalyticBrdf's values (the same operations in the
// same order); deploy/materials/{paint,glossy,brushed}.toml write the same materials as files.
// Pure.
#pragma once

#include <string>

#include "core/analytic_brdf.h"
#include "core/material/material.h"

namespace brdf::material {

Material FromAnalytic(const AnalyticBrdfParams& params, std::string name);

// AnalyticBrdf::PaintLike(), Glossy() and Brushed() as materials, named "paint-like", "glossy"
// and "brushed (anisotropic)".
Material PaintMaterial();
Material GlossyMaterial();
Material BrushedMaterial();

}  // namespace brdf::material
