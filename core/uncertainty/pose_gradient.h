// The sensitivity of each sample reading to an error of the stage's pose (docs/uncertainty.md,
// "Pose"), estimated from the session's neighbouring sample readings. A reading reported at pose p
// was taken at p + Δp: the meter saw the sample's radiance there, f(p + Δp) · cos θi(p + Δp), and
// brdfd divided it by cos θi(p). The sensitivity per axis a is therefore
//     ∂f_reported/∂pₐ = ∂(f · cos θi)/∂pₐ / cos θi(p),
// the gradient of the radiance factor f · cos θi, which the neighbours give: along each axis, the
// central difference between the nearest readings below and above with the other three axes
// equal, one-sided at an edge. An axis with no such neighbour has no estimate (an empty vector).
// The grid's step smooths a narrow peak: near one this underestimates the gradient. Pure: no I/O.
#pragma once

#include <array>
#include <cstddef>
#include <span>
#include <vector>

#include "core/pose.h"

namespace brdf::uncertainty {

// One sample reading as its neighbours see it.
struct PosedValue {
  Pose pose;                  // as reported (degrees)
  double theta_i_deg = 0;     // its incidence at that pose, in [0°, 90°)
  std::vector<double> value;  // the quantity per band (every reading the same number of bands)
};

// Per axis (α, β, γ, δ): ∂f/∂p per band, per degree, or empty where the axis has no neighbour.
using PoseGradient = std::array<std::vector<double>, 4>;

// Each reading's gradient, in the order given. Readings count as on one line along an axis when
// their other three axes agree within 1e-3°; two readings at the same pose are not neighbours of
// each other (a repeat gives no slope), and a neighbouring position's repeats count as their mean
// (so does the reading's own position at an edge). Readings whose band counts differ from the
// first's, or whose θi is outside [0°, 90°), get no gradient on any axis.
std::vector<PoseGradient> EstimatePoseGradients(std::span<const PosedValue> readings);

}  // namespace brdf::uncertainty
