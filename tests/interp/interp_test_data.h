// Data sets for the interpolation tests, generated here independently of the code under test:
// the paper's rig grid from geometry.md's closed forms, uniform random sets, integer lattices, and
// spectra that are linear in the coordinates or come from the analytic BRDF.
#pragma once

#include <array>
#include <cstdint>
#include <functional>
#include <memory>
#include <random>
#include <vector>

#include "core/interp/interpolator.h"

namespace brdf::interp::testing {

using Point = std::vector<double>;

// The sample-rotation grid of geometry.md (δ = 0 … 146.25 step 11.25, α = 0 … 70 step 10,
// β every 5° with θi, θo ≤ 89.999°), converted with cos θi = cos α cos β,
// cos θo = cos α cos(β − δ), cos δ = cos θi cos θo + sin θi sin θo cos φ, distinct points only
// (first seen kept). `poses` receives the number of poses before removing duplicates.
std::vector<Point> PaperGrid(int* poses = nullptr);

// n random rig poses (α in [0°, 70°], β in [−175°, 180°], δ in [0°, 146.25°], uniform) as
// (θi, θo, φ), both directions within 89.999° of the normal, from geometry.md's closed forms.
std::vector<Point> RigPoseQueries(std::size_t n, std::uint64_t seed);

// n points uniform in the box [lo[j], hi[j]).
std::vector<Point> RandomPoints(std::size_t n, const std::vector<double>& lo,
                                const std::vector<double>& hi, std::uint64_t seed);

// All integer points of [0, size)^dims (spacing `step`), in row-major order.
std::vector<Point> Lattice(int dims, int size, double step = 1.0);

// A spectrum as a function of the coordinates.
using SpectrumFn = std::function<std::vector<double>(const Point&)>;

// `bands` values, each an affine function of the coordinates with fixed, band-dependent
// coefficients (so that every band differs).
SpectrumFn LinearSpectrum(int dims, int bands);
// The analytic paint-like (3D) or brushed (4D) BRDF on the PR-650 grid (101 bands).
SpectrumFn AnalyticSpectrum(int dims);

// A SampleSet of the points with ids first_id, first_id + 1, …
std::shared_ptr<SampleSet> MakeSamples(const std::vector<Point>& points, const SpectrumFn& fn,
                                       std::int64_t first_id = 0);

}  // namespace brdf::interp::testing
