// A model evaluation as text: a '#' comment block with the models, how they were fitted and the
// overall residuals, then one CSV row per band with every model's parameters and residuals:
//   wavelength_nm,lambert_albedo,lambert_rms,lambert_rel_rms,ct_kd,ct_ks,ct_alpha,ct_f0,
//   ct_rms,ct_rel_rms
// (the columns of a model that was not fitted are left out).
#pragma once

#include <cstdint>
#include <string>

#include "core/fit/fit.h"

namespace brdf::fit {

struct FitReportInfo {
  std::int64_t session_id = 0;
  std::string session_name;
  std::size_t observations = 0;
  std::size_t left_out = 0;  // sample readings without a usable BRDF
};

// Either fit may be null (not fitted); the grids must match when both are given.
std::string FitReportCsv(const FitReportInfo& info, const LambertFit* lambert,
                         const CookTorranceFit* cook_torrance);

// One line per fitted model with its overall residuals, for a terminal.
std::string FitSummary(const LambertFit* lambert, const CookTorranceFit* cook_torrance);

}  // namespace brdf::fit
