#include "tools/brdf-sim/optics/truth.h"

#include <cmath>
#include <cstdio>
#include <string>

#include "core/json_text.h"
#include "tools/brdf-sim/optics/material.h"
#include "tools/brdf-sim/optics/optics.h"

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
  if (!q.material_path.empty() && (q.anisotropic || q.glossy)) {
    return InvalidArgument(
        "truth: --material and --anisotropic/--glossy name two samples; give one");
  }
  return Status::Ok();
}

Result<material::Material> TruthSample(const TruthQuery& query, const OpticsConfig& run) {
  BRDF_RETURN_IF_ERROR(ValidateTruthQuery(query));
  // The query names the sample, or else the run does.
  const bool query_names_one = !query.material_path.empty() || query.anisotropic || query.glossy;
  TruthQuery merged = query;
  if (!query_names_one) {
    merged.material_path = run.material_path;
    merged.anisotropic = run.anisotropic;
    merged.glossy = run.glossy;
    BRDF_RETURN_IF_ERROR(ValidateTruthQuery(merged));
  }
  if (merged.material_path.empty()) return SampleMaterial(merged.anisotropic, merged.glossy);
  return LoadMaterialFile(merged.material_path);
}

std::string FormatTruth(const TruthQuery& q) {
  return FormatTruth(q, SampleMaterial(q.anisotropic, q.glossy));
}

std::string FormatTruth(const TruthQuery& q, const material::Material& sample,
                        const WavelengthGrid& grid) {
  const std::vector<double> f = sample.EvaluateSpectrum(q.directions, grid);
  const Directions& d = q.directions;
  std::string out;
  if (q.json) {
    out += "{\"theta_i\":" + Number(d.theta_i) + ",\"phi_i\":" + Number(d.phi_i) +
           ",\"theta_o\":" + Number(d.theta_o) + ",\"phi_o\":" + Number(d.phi_o) +
           ",\"anisotropic\":" + (sample.anisotropic() ? "true" : "false") +
           ",\"sample\":" + JsonString(sample.name()) + ",\"unit\":\"sr^-1\",\"wavelength_nm\":[";
    for (std::size_t k = 0; k < grid.count; ++k) out += (k ? "," : "") + Number(grid.at(k));
    out += "],\"brdf\":[";
    for (std::size_t k = 0; k < f.size(); ++k) out += (k ? "," : "") + Number(f[k]);
    out += "]}\n";
    return out;
  }
  out += "# true BRDF (sr^-1) of the " + sample.name() + " sample at theta_i " + Number(d.theta_i) +
         " phi_i " + Number(d.phi_i) + " theta_o " + Number(d.theta_o) + " phi_o " +
         Number(d.phi_o) + " (deg)\n";
  for (std::size_t k = 0; k < f.size(); ++k) out += Number(grid.at(k)) + " " + Number(f[k]) + "\n";
  return out;
}

}  // namespace brdf::sim
