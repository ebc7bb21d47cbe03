#include "tools/brdf-interp/synthetic_samples.h"

#include <random>

#include "core/geometry.h"

namespace brdf::interp_tool {

Result<SyntheticPoints> PaperGridPoints() {
  const GridSpec spec;  // the paper's loops
  Result<std::vector<Pose>> poses = ExpandSampleRotationGrid(spec);
  if (!poses.ok()) return poses.status().WithContext("expanding the paper's grid");
  std::vector<IsoDirection> iso;
  iso.reserve(poses->size());
  for (const Pose& pose : *poses) iso.push_back(ToIsotropic(PoseToDirections(pose)));
  SyntheticPoints out;
  out.dims = 3;
  out.poses = static_cast<int>(poses->size());
  for (const IsoDirection& p : DistinctIsoPoints(iso)) {
    out.coords.insert(out.coords.end(), {p.theta_i, p.theta_o, p.phi});
  }
  return out;
}

SyntheticPoints RandomPoints(std::size_t n, std::uint64_t seed, int dims) {
  std::mt19937_64 rng(seed);
  auto uniform = [&rng](double hi) { return hi * static_cast<double>(rng() >> 11) * 0x1.0p-53; };
  SyntheticPoints out;
  out.dims = dims;
  out.coords.reserve(n * static_cast<std::size_t>(dims));
  for (std::size_t i = 0; i < n; ++i) {
    if (dims == 3) {
      out.coords.push_back(uniform(90));
      out.coords.push_back(uniform(90));
      out.coords.push_back(uniform(360));
    } else {
      out.coords.push_back(uniform(90));
      out.coords.push_back(uniform(360));
      out.coords.push_back(uniform(90));
      out.coords.push_back(uniform(360));
    }
  }
  return out;
}

AnalyticBrdf SyntheticBrdf(int dims) {
  return dims == 3 ? AnalyticBrdf::PaintLike() : AnalyticBrdf::Brushed();
}

Directions PointDirections(std::span<const double> p) {
  if (p.size() == 3) return {p[0], 0.0, p[1], p[2]};
  return {p[0], p[1], p[2], p[3]};
}

std::shared_ptr<interp::SampleSet> SyntheticSamples(const SyntheticPoints& points,
                                                    const WavelengthGrid& grid) {
  return SyntheticSamples(points, grid, SyntheticBrdf(points.dims));
}

std::shared_ptr<interp::SampleSet> SyntheticSamples(const SyntheticPoints& points,
                                                    const WavelengthGrid& grid,
                                                    const AnalyticBrdf& brdf) {
  auto set = std::make_shared<interp::SampleSet>(points.dims, static_cast<int>(grid.count));
  const auto d = static_cast<std::size_t>(points.dims);
  std::vector<double> spectrum(grid.count);
  for (std::size_t i = 0; i < points.size(); ++i) {
    const std::span<const double> p(points.coords.data() + i * d, d);
    brdf.EvaluateSpectrum(PointDirections(p), grid, spectrum);
    // Finite coordinates and spectra by construction: Add cannot fail.
    (void)set->Add(static_cast<std::int64_t>(i), p, spectrum);
  }
  return set;
}

}  // namespace brdf::interp_tool
