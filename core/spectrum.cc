#include "core/spectrum.h"

#include <algorithm>
#include <cmath>
#include <numbers>
#include <sstream>

namespace brdf {
namespace {

constexpr double kDegToRad = std::numbers::pi / 180.0;

std::string Fmt(double v) {
  std::ostringstream s;
  s.precision(10);
  s << v;
  return s.str();
}

std::string BandText(const WavelengthGrid& g, std::size_t k) {
  return Fmt(g.at(k)) + " nm (band " + std::to_string(k) + ")";
}

Status SameGrid(const Spectrum& a, const std::string& a_name, const Spectrum& b,
                const std::string& b_name) {
  if (a.grid == b.grid) return Status::Ok();
  return InvalidArgument("the " + a_name + " is on " + GridText(a.grid) + " but the " + b_name +
                         " is on " + GridText(b.grid) + "; resample one onto the other's grid");
}

Status CheckIncidence(double deg, const char* name) {
  if (!std::isfinite(deg) || deg < 0 || deg >= 90) {
    return InvalidArgument(std::string(name) + " = " + Fmt(deg) +
                           "° is outside [0°, 90°): the lamp must be above the surface and not "
                           "grazing for the cosine correction");
  }
  return Status::Ok();
}

Status CheckWhite(double rho, const std::string& where) {
  if (!std::isfinite(rho) || rho <= 0) {
    return InvalidArgument("white standard reflectance " + where + " is " + Fmt(rho) +
                           "; give the standard's calibrated reflectance (0.99 for the RS-3)");
  }
  return Status::Ok();
}

// f = R · ρw(k) / π · scale, with scale = cos θi,ref / cos θi (or its inverse and π/ρw).
template <typename WhiteAt>
Result<Spectrum> ScaleByWhite(const Spectrum& in, const std::string& in_name, WhiteAt white_at,
                              double theta_i_ref_deg, double theta_i_deg, bool to_brdf) {
  BRDF_RETURN_IF_ERROR(ValidateSpectrum(in, in_name));
  BRDF_RETURN_IF_ERROR(CheckIncidence(theta_i_ref_deg, "theta_i_ref (reference incidence)"));
  BRDF_RETURN_IF_ERROR(CheckIncidence(theta_i_deg, "theta_i (sample incidence)"));
  const double cos_ratio =
      std::cos(theta_i_ref_deg * kDegToRad) / std::cos(theta_i_deg * kDegToRad);
  Spectrum out{in.grid, std::vector<double>(in.values.size())};
  for (std::size_t k = 0; k < in.values.size(); ++k) {
    const double rho = white_at(k);
    out.values[k] = to_brdf ? in.values[k] * rho / std::numbers::pi * cos_ratio
                            : in.values[k] * std::numbers::pi / rho / cos_ratio;
  }
  return out;
}

}  // namespace

std::string GridText(const WavelengthGrid& g) {
  return Fmt(g.start_nm) + "–" + Fmt(g.last_nm()) + " nm every " + Fmt(g.step_nm) + " nm (" +
         std::to_string(g.count) + " bands)";
}

Status ValidateSpectrum(const Spectrum& s, const std::string& what) {
  if (!s.grid.valid()) {
    return InvalidArgument("the " + what + " has an invalid wavelength grid (start " +
                           Fmt(s.grid.start_nm) + " nm, step " + Fmt(s.grid.step_nm) + " nm, " +
                           std::to_string(s.grid.count) +
                           " bands); it needs a positive step "
                           "and at least one band");
  }
  if (s.values.size() != s.grid.count) {
    return InvalidArgument("the " + what + " has " + std::to_string(s.values.size()) +
                           " values for " + GridText(s.grid) + "; there must be one per band");
  }
  for (std::size_t k = 0; k < s.values.size(); ++k) {
    if (!std::isfinite(s.values[k])) {
      return InvalidArgument("the " + what + " is not finite at " + BandText(s.grid, k) +
                             "; re-take the reading");
    }
  }
  return Status::Ok();
}

Result<Spectrum> Reflectance(const Spectrum& sample, const Spectrum& white) {
  BRDF_RETURN_IF_ERROR(ValidateSpectrum(sample, "sample reading"));
  BRDF_RETURN_IF_ERROR(ValidateSpectrum(white, "white reference"));
  BRDF_RETURN_IF_ERROR(SameGrid(sample, "sample reading", white, "white reference"));
  Spectrum r{sample.grid, std::vector<double>(sample.values.size())};
  for (std::size_t k = 0; k < r.values.size(); ++k) {
    if (white.values[k] <= 0) {
      return InvalidArgument("reflectance: the white reference reads " + Fmt(white.values[k]) +
                             " at " + BandText(white.grid, k) +
                             "; it must be positive to divide by: check the lamp and re-take the "
                             "reference");
    }
    r.values[k] = sample.values[k] / white.values[k];
  }
  return r;
}

Result<Spectrum> Reflectance(const Spectrum& sample, const Spectrum& white, const Spectrum& dark) {
  BRDF_RETURN_IF_ERROR(ValidateSpectrum(sample, "sample reading"));
  BRDF_RETURN_IF_ERROR(ValidateSpectrum(white, "white reference"));
  BRDF_RETURN_IF_ERROR(ValidateSpectrum(dark, "dark reading"));
  BRDF_RETURN_IF_ERROR(SameGrid(sample, "sample reading", white, "white reference"));
  BRDF_RETURN_IF_ERROR(SameGrid(sample, "sample reading", dark, "dark reading"));
  Spectrum r{sample.grid, std::vector<double>(sample.values.size())};
  for (std::size_t k = 0; k < r.values.size(); ++k) {
    const double denom = white.values[k] - dark.values[k];
    if (denom <= 0) {
      return InvalidArgument("reflectance: the white reference minus the dark reading is " +
                             Fmt(denom) + " at " + BandText(white.grid, k) +
                             "; it must be positive to divide by: check the lamp, the dark "
                             "reading, and re-take the reference");
    }
    r.values[k] = (sample.values[k] - dark.values[k]) / denom;
  }
  return r;
}

Result<Spectrum> BrdfFromReflectance(const Spectrum& reflectance, const Spectrum& white_reflectance,
                                     double theta_i_ref_deg, double theta_i_deg) {
  BRDF_RETURN_IF_ERROR(ValidateSpectrum(white_reflectance, "white standard reflectance"));
  BRDF_RETURN_IF_ERROR(
      SameGrid(reflectance, "reflectance", white_reflectance, "white standard reflectance"));
  for (std::size_t k = 0; k < white_reflectance.values.size(); ++k) {
    BRDF_RETURN_IF_ERROR(
        CheckWhite(white_reflectance.values[k], "at " + BandText(white_reflectance.grid, k)));
  }
  return ScaleByWhite(
      reflectance, "reflectance", [&](std::size_t k) { return white_reflectance.values[k]; },
      theta_i_ref_deg, theta_i_deg, true);
}

Result<Spectrum> BrdfFromReflectance(const Spectrum& reflectance, double white_reflectance,
                                     double theta_i_ref_deg, double theta_i_deg) {
  BRDF_RETURN_IF_ERROR(CheckWhite(white_reflectance, "(constant)"));
  return ScaleByWhite(
      reflectance, "reflectance", [&](std::size_t) { return white_reflectance; }, theta_i_ref_deg,
      theta_i_deg, true);
}

Result<Spectrum> ReflectanceFromBrdf(const Spectrum& brdf, double white_reflectance,
                                     double theta_i_ref_deg, double theta_i_deg) {
  BRDF_RETURN_IF_ERROR(CheckWhite(white_reflectance, "(constant)"));
  return ScaleByWhite(
      brdf, "BRDF", [&](std::size_t) { return white_reflectance; }, theta_i_ref_deg, theta_i_deg,
      false);
}

Result<Spectrum> Resample(const Spectrum& s, const WavelengthGrid& target) {
  BRDF_RETURN_IF_ERROR(ValidateSpectrum(s, "spectrum to resample"));
  if (!target.valid()) {
    return InvalidArgument("resample: the target grid is invalid (step " + Fmt(target.step_nm) +
                           " nm, " + std::to_string(target.count) +
                           " bands); it needs a positive step and at least one band");
  }
  constexpr double kSlackNm = 1e-9;
  const double lo = s.grid.start_nm, hi = s.grid.last_nm();
  Spectrum out{target, std::vector<double>(target.count)};
  for (std::size_t k = 0; k < target.count; ++k) {
    const double nm = target.at(k);
    if (nm < lo - kSlackNm || nm > hi + kSlackNm) {
      return InvalidArgument("resample: " + Fmt(nm) + " nm (target band " + std::to_string(k) +
                             ") is outside the source's " + GridText(s.grid) +
                             "; narrow the target grid (no extrapolation)");
    }
    const double u =
        std::clamp((nm - lo) / s.grid.step_nm, 0.0, static_cast<double>(s.grid.count - 1));
    const std::size_t j = std::min(static_cast<std::size_t>(u), s.grid.count - 1);
    const double w = u - static_cast<double>(j);
    out.values[k] =
        j + 1 < s.grid.count ? s.values[j] * (1.0 - w) + s.values[j + 1] * w : s.values[j];
  }
  return out;
}

}  // namespace brdf
