// Synthetic sample sets for the demo, the benchmarks and the cross-checks: where the rig would
// measure, and what a known (analytic) sample would give there.
//   Paper grid: the sample-rotation loops of geometry.md (core/geometry.h, GridSpec defaults:
//     2,320 poses), reduced to the 2,153 distinct (θi, θo, φ) points, first seen kept.
//   Random: n points uniform in [0,90)×[0,90)×[0,360) (3D, as measured in interpolation.md) or
//     (θi, φi, θo, φo) in [0,90)×[0,360)×[0,90)×[0,360) (4D), from a seeded mt19937_64 with 53-bit
//     mantissas, so the same seed gives the same file everywhere.
// Spectra: AnalyticBrdf::PaintLike() (3D) or ::Brushed() (4D) on the PR-650 grid, 380–780 nm
// every 4 nm. A 3D point (θi, θo, φ) is evaluated at the directions (θi, 0, θo, φ).
#pragma once

#include <cstdint>
#include <memory>
#include <vector>

#include "core/analytic_brdf.h"
#include "core/interp/interpolator.h"
#include "core/status.h"
#include "core/wavelength_grid.h"

namespace brdf::interp_tool {

struct SyntheticPoints {
  int dims = 3;
  std::vector<double> coords;  // size × dims
  int poses = 0;               // paper grid: poses before removing duplicates
  std::size_t size() const { return coords.size() / static_cast<std::size_t>(dims); }
};

Result<SyntheticPoints> PaperGridPoints();
SyntheticPoints RandomPoints(std::size_t n, std::uint64_t seed, int dims);

// The analytic sample for the data's dimensionality.
AnalyticBrdf SyntheticBrdf(int dims);
// Directions of a 3D or 4D point (see above).
Directions PointDirections(std::span<const double> point);
// A SampleSet of the points with the analytic spectra; ids are the point indices.
std::shared_ptr<interp::SampleSet> SyntheticSamples(const SyntheticPoints& points,
                                                    const WavelengthGrid& grid);
// The same with another known sample.
std::shared_ptr<interp::SampleSet> SyntheticSamples(const SyntheticPoints& points,
                                                    const WavelengthGrid& grid,
                                                    const AnalyticBrdf& brdf);

}  // namespace brdf::interp_tool
