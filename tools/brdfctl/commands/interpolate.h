// `brdfctl interpolate <id> --theta-i A --theta-o B (--phi C | --phi-i D --phi-o E)`: the spectrum
// at one direction from a session's readings (Interpolation.Interpolate), as a table of
// wavelength and value in the quantity's unit.
// --explain adds the blended readings: their ids, positions and weights, and each one's own
// spectrum next to the interpolated one (fetched with one InterpolateBatch call, nearest method,
// at the vertices' positions), so the blend can be checked by eye.
// The table carries the expanded uncertainties U = k · u (--k, default 2) of the interpolated
// value: the measurement part (the blended readings' budgets, shared terms correlated), the
// interpolation term and their combination (InterpolationResult.uncertainty, docs/uncertainty.md
// "Interpolated values"), and names what was not estimated; --no-uncertainty leaves them out.
// --json: the InterpolateResponse on one line; with --explain then one InterpolationResult line
// per vertex. Exit 4 when the method gives no spectrum there (status and detail are printed).
#pragma once

#include <optional>
#include <string>
#include <vector>

#include "tools/brdfctl/command.h"
#include "tools/brdfctl/command_context.h"

namespace brdf::ctl {

struct InterpolateOptions {
  std::string session_id;
  double theta_i = 0;
  double theta_o = 0;
  std::optional<double> phi;    // isotropic form
  std::optional<double> phi_i;  // four-angle form (with phi_o)
  std::optional<double> phi_o;
  std::string method = "octant";  // octant, delaunay, nearest
  std::string quantity = "brdf";  // radiance, reflectance, brdf
  bool explain = false;
  bool mirror_phi = false;
  bool reciprocity = false;
  std::vector<double> axis_scale;
  std::string coordinates = "incidence";  // incidence or half-diff (isotropic sessions)
  std::string trend = "none";             // none or bivariate (isotropic sessions)
  int every = 1;                          // print every Nth band
  double k = 2;                           // coverage factor of the ± columns
  bool uncertainty = true;                // ask for and show the uncertainty
};

int RunInterpolate(CommandContext& ctx, const InterpolateOptions& options);

// `interpolate`, with its flags (command.h).
void RegisterInterpolateCommand(CommandRegistry& registry);

}  // namespace brdf::ctl
