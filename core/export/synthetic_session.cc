#include "core/export/synthetic_session.h"

#include <cmath>

namespace brdf::exports {
namespace {

constexpr double kDarkRadiance = 2e-4;

}  // namespace

double SyntheticLampRadiance(double wavelength_nm) {
  return 0.01 + 0.03 * (wavelength_nm - 380.0) / 400.0;
}

Result<Session> SyntheticSession(const AnalyticBrdf& brdf, const SyntheticSessionOptions& options) {
  BRDF_ASSIGN_OR_RETURN(std::vector<Pose> poses, ExpandSampleRotationGrid(options.poses));
  const WavelengthGrid& grid = options.grid;
  if (!grid.valid()) return InvalidArgument("synthetic session: the wavelength grid is invalid");

  Session session;
  session.id = 1;
  session.name = "synthetic paint-like sample";
  session.white_reflectance = options.white_reflectance;
  std::int64_t next_id = 1;

  Reading reference;
  reference.id = next_id++;
  reference.kind = ReadingKind::kReference;
  reference.directions = PoseToDirections(reference.pose);
  reference.spectrum = Spectrum{grid, std::vector<double>(grid.count)};
  for (std::size_t b = 0; b < grid.count; ++b) {
    reference.spectrum.values[b] =
        SyntheticLampRadiance(grid.at(b)) + (options.with_dark ? kDarkRadiance : 0.0);
  }
  session.readings.push_back(reference);

  std::optional<std::int64_t> dark_id;
  if (options.with_dark) {
    Reading dark;
    dark.id = next_id++;
    dark.kind = ReadingKind::kDark;
    dark.directions = reference.directions;
    dark.spectrum = Spectrum{grid, std::vector<double>(grid.count, kDarkRadiance)};
    dark_id = dark.id;
    session.readings.push_back(dark);
  }

  for (const Pose& pose : poses) {
    Reading r;
    r.id = next_id++;
    r.kind = ReadingKind::kSample;
    r.pose = pose;
    r.directions = PoseToDirections(pose);
    r.reference_id = reference.id;
    r.dark_id = dark_id;
    const Spectrum f{grid, brdf.EvaluateSpectrum(r.directions, grid)};
    Result<Spectrum> reflectance = ReflectanceFromBrdf(
        f, options.white_reflectance, reference.directions.theta_i, r.directions.theta_i);
    if (!reflectance.ok()) return reflectance.status().WithContext("synthetic pose");
    r.spectrum = Spectrum{grid, std::vector<double>(grid.count)};
    for (std::size_t b = 0; b < grid.count; ++b) {
      const double d = options.with_dark ? kDarkRadiance : 0.0;
      r.spectrum.values[b] = reflectance->values[b] * SyntheticLampRadiance(grid.at(b)) + d;
    }
    session.readings.push_back(std::move(r));
  }
  return session;
}

}  // namespace brdf::exports
