#include "tools/brdf-sim/optics/errors_settings.h"

#include <CLI/CLI.hpp>
#include <cmath>
#include <string>

namespace brdf::sim {
namespace {

// One error source as a key of [optics.errors] and a flag: where it is, its range, its help.
struct Setting {
  const char* key;
  const char* flag;
  double ErrorSources::*field;
  double lo, hi;
  const char* help;
};

constexpr Setting kSettings[] = {
    {"gain_noise", "--gain-noise", &ErrorSources::gain_noise, 0, 0.2,
     "Relative sigma of the meter's gain, drawn per measurement (0 = off)"},
    {"lamp_drift_per_hour", "--lamp-drift", &ErrorSources::lamp_drift_per_hour, -0.5, 0.5,
     "Relative change of the lamp's output per simulated hour of measuring (0 = off)"},
    {"lamp_wander_per_sqrt_hour", "--lamp-wander", &ErrorSources::lamp_wander_per_sqrt_hour, 0, 0.5,
     "Relative sigma of the lamp's random walk per sqrt(simulated hour) (0 = off)"},
    {"white_error", "--white-error", &ErrorSources::white_error, 0, 0.1,
     "Relative sigma of the white standard's true reflectance, drawn once per run (0 = off)"},
    {"pose_jitter_deg", "--pose-jitter", &ErrorSources::pose_jitter_deg, 0, 5,
     "Sigma of each axis's true position about the reported one, deg, per measurement"},
    {"wavelength_shift_nm", "--wavelength-shift", &ErrorSources::wavelength_shift_nm, -10, 10,
     "The meter's wavelength scale is off by this many nm"},
    {"wavelength_shift_sigma_nm", "--wavelength-shift-sigma",
     &ErrorSources::wavelength_shift_sigma_nm, 0, 10,
     "... plus a shift drawn once per run with this sigma, nm"},
    {"stray_light", "--stray-light", &ErrorSources::stray_light, 0, 0.1,
     "Fraction of the lamp's light reaching the detector by other paths (0 = off)"},
};

std::string Num(double v) {
  char buf[32];
  std::snprintf(buf, sizeof buf, "%g", v);
  return buf;
}

}  // namespace

void ReadErrorSources(toml_keys::TableReader& errors, ErrorSources& out) {
  for (const Setting& s : kSettings) errors.Double(s.key, out.*(s.field), s.lo, s.hi);
  errors.Finish();
}

void AddErrorFlags(CLI::App& app, ErrorSources& out) {
  for (const Setting& s : kSettings) app.add_option(s.flag, out.*(s.field), s.help);
}

Status ValidateErrorSources(const ErrorSources& e) {
  for (const Setting& s : kSettings) {
    const double v = e.*(s.field);
    if (!std::isfinite(v) || v < s.lo || v > s.hi) {
      return InvalidArgument("optics.errors." + std::string(s.key) + " = " + Num(v) +
                             " is outside [" + Num(s.lo) + ", " + Num(s.hi) + "]; fix " + s.flag +
                             " or [optics.errors] " + s.key);
    }
  }
  return Status::Ok();
}

}  // namespace brdf::sim
