// A model evaluation as text: a '#' comment block with the models, how they were fitted ("GLS with
// N shared terms", "weighted, independent" or unweighted), the overall residuals and χ²/dof, then
// one CSV row per band with every model's parameters, their standard uncertainties (k = 1; _u) and
// residuals:
//   wavelength_nm,lambert_albedo,lambert_albedo_u,lambert_rms,lambert_rel_rms,
//   ct_kd,ct_kd_u,ct_ks,ct_ks_u,ct_alpha,ct_alpha_u,ct_f0,ct_f0_u,ct_rms,ct_rel_rms
// (the columns of a model that was not fitted are left out; nan: not determined).
#pragma once

#include <cstdint>
#include <string>

#include "core/fit/fit.h"

namespace brdf::fit {

struct FitReportInfo {
  std::int64_t session_id = 0;
  std::string session_name;
  std::size_t observations = 0;
  std::size_t left_out = 0;          // sample readings without a usable BRDF
  std::size_t with_uncertainty = 0;  // readings that carried a standard uncertainty
};

// Either fit may be null (not fitted); the grids must match when both are given.
std::string FitReportCsv(const FitReportInfo& info, const LambertFit* lambert,
                         const CookTorranceFit* cook_torrance);

// One line per fitted model with its overall residuals and χ²/dof, for a terminal.
std::string FitSummary(const LambertFit* lambert, const CookTorranceFit* cook_torrance);

}  // namespace brdf::fit
