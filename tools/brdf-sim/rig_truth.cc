#include "tools/brdf-sim/rig_truth.h"

#include <cmath>
#include <cstdio>
#include <string>

#include "tools/brdf-sim/optics.h"

namespace brdf::sim {
namespace {

std::string Number(double x) {
  char buf[40];
  std::snprintf(buf, sizeof buf, "%.17g", x);
  return buf;
}

}  // namespace

Status ValidateTruthQuery(const TruthQuery& q) {
  const Directions& d = q.directions;
  if (!std::isfinite(d.theta_i)) return InvalidArgument("truth: --theta-i must be a finite angle");
  if (!std::isfinite(d.theta_o)) return InvalidArgument("truth: --theta-o must be a finite angle");
  if (!std::isfinite(d.phi_i) || !std::isfinite(d.phi_o)) {
    return InvalidArgument("truth: --phi, --phi-i and --phi-o must be finite angles");
  }
  if (q.anisotropic && q.glossy) {
    return InvalidArgument("truth: --anisotropic and --glossy name two samples; give one");
  }
  return Status::Ok();
}

std::string FormatTruth(const TruthQuery& q) {
  const WavelengthGrid grid = WavelengthGrid::Pr650();
  const std::vector<double> f = TrueBrdf(q.directions, q.anisotropic, q.glossy);
  const Directions& d = q.directions;
  std::string out;
  if (q.json) {
    out += "{\"theta_i\":" + Number(d.theta_i) + ",\"phi_i\":" + Number(d.phi_i) +
           ",\"theta_o\":" + Number(d.theta_o) + ",\"phi_o\":" + Number(d.phi_o) +
           ",\"anisotropic\":" + (q.anisotropic ? "true" : "false") + ",\"sample\":\"" +
           SampleName(q.anisotropic, q.glossy) + "\"" + ",\"unit\":\"sr^-1\",\"wavelength_nm\":[";
    for (std::size_t k = 0; k < grid.count; ++k) out += (k ? "," : "") + Number(grid.at(k));
    out += "],\"brdf\":[";
    for (std::size_t k = 0; k < f.size(); ++k) out += (k ? "," : "") + Number(f[k]);
    out += "]}\n";
    return out;
  }
  out += "# true BRDF (sr^-1) of the " + std::string(SampleName(q.anisotropic, q.glossy)) +
         " sample at theta_i " + Number(d.theta_i) + " phi_i " + Number(d.phi_i) + " theta_o " +
         Number(d.theta_o) + " phi_o " + Number(d.phi_o) + " (deg)\n";
  for (std::size_t k = 0; k < f.size(); ++k) out += Number(grid.at(k)) + " " + Number(f[k]) + "\n";
  return out;
}

}  // namespace brdf::sim
