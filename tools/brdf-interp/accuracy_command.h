// `brdf-interp accuracy`: how close each method comes to a known BRDF, in both coordinate systems.
// "Measures" an analytic sample (core/analytic_brdf.h: the simulator's paint-like sample, and a
// glossy variant) on the paper's rig grid (2,153 distinct points), interpolates it at random rig
// poses (α in [0°, 70°], β in [−175°, 180°], δ in [0°, 146.25°], uniform, both directions within
// 89.999° of the normal, seeded) with octant, Delaunay and nearest, each in (θi, θo, φ) and in
// (θh, θd, φd), and prints per sample and method:
//   ok        the queries answered;
//   RMS       sqrt(mean (value − truth)²) over all bands of the queries that EVERY row of the
//             sample answered, as a percentage of the mean truth there (a common set, so rows
//             compare like with like);
//   RMS θh<10 the same over those of the common queries within 10° of the specular
//             configuration (the half vector within 10° of the normal);
//   peak      the relative error at the specular-peak query (42.5°, 42.5°, 177.5°) in the band
//             nearest 550 nm ("failed" when the method has no answer there).
// Samples: paint, glossy, and glossy-ct: the paint's diffuse base under a Cook-Torrance lobe
// (GGX α 0.1, Schlick F0 0.04, Smith shadowing, ks 4; core/fit/models.h), a glossy sample that,
// unlike the two Blinn-Phong ones, is not a function of (θh, θd) alone: for judging the bivariate
// trend fairly.
// blend "log" blends the vertices' spectra geometrically, band by band: the interpolators run on
// log(max(f, floor_b)) and their answers are exponentiated, i.e. f = exp(Σ w_k · log(max(f_k,
// floor_b))), where floor_b is 1e-6 of band b's largest sampled value (a zero or negative
// reading then pulls the blend down hard but stays finite). Nearest neighbour is unaffected.
#pragma once

#include <cstdint>
#include <ostream>
#include <string>

namespace brdf::interp_tool {

struct AccuracyRequest {
  std::string sample = "both";  // paint | glossy | glossy-ct | both (paint, glossy) | all
  std::size_t queries = 20000;
  std::uint64_t seed = 19;
  std::string scale;       // axis scales for (θi, θo, φ); "" = none
  std::string half_scale;  // axis scales for (θh·cos φd, θh·sin φd, θd); "" = the default
  bool mirror_phi = false;
  bool reciprocity = false;
  std::string blend = "linear";  // linear | log (see above)
  std::string trend = "none";    // none | bivariate (core/interp/trend.h), for every method
  double noise = 0;  // each reading × (1 + noise · N(0, 1)), one draw per reading; the truth not
};

int RunAccuracy(const AccuracyRequest& request, std::ostream& out, std::ostream& err);

}  // namespace brdf::interp_tool
