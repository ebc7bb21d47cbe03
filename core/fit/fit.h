// Evaluation of analytic reflection models against measured BRDFs, wavelength by wavelength (the
// paper's "evaluation of existing analytic models"): Lambert, and Cook-Torrance with a GGX
// distribution (models.h). Least squares on the BRDF values themselves (sr⁻¹) when every
// observation carries its standard uncertainty (Observations::weighted()): generalised least
// squares, weighted by V⁻¹ with the shared sources' covariance (band_covariance.h), when the
// observations name shared sources; by 1/u² when every u is independent; else every value alike.
// Each fit reports how it weighted (FitStatistics::weighting), its parameters' standard
// uncertainties and χ²/dof (fit_statistics.h: unscaled (JᵀV⁻¹J)⁻¹ when weighted, scaled by the
// residual variance when not).
//
// Cook-Torrance's parameters: kd(λ) and ks(λ) per band; the roughness α and Schlick's F0 shared
// by all bands (default: the microfacet geometry does not depend on wavelength, and a coloured
// highlight is carried by ks(λ)) or fitted per band (ParameterSharing::kPerBand). For a given
// (α, F0) the model is linear in (kd, ks), so those are solved exactly per band (non-negative
// least squares of two unknowns) and a Nelder-Mead search runs over (log α, logit F0) only,
// from several starting roughnesses. F0 only shapes the Fresnel rise toward grazing θd: data that
// do not reach grazing angles pin it down poorly (ks · F0 is then the well-determined product).
#pragma once

#include <functional>
#include <vector>

#include "core/call_context.h"
#include "core/fit/band_covariance.h"
#include "core/fit/fit_statistics.h"
#include "core/fit/models.h"
#include "core/fit/observations.h"
#include "core/status.h"

namespace brdf::fit {

// How far a model is from the data.
struct Residuals {
  std::size_t count = 0;    // values compared
  double rms = 0;           // √(Σ r² / count), sr⁻¹
  double relative_rms = 0;  // √(Σ r² / Σ f²): 0 is a perfect fit, 1 no better than f = 0
  double max_abs = 0;       // largest |r|, sr⁻¹
};

struct LambertFit {
  WavelengthGrid grid;
  std::vector<double> albedo;             // ρ per band: π · (GLS-weighted) mean f
  std::vector<double> albedo_u;           // its standard uncertainty per band
  FitStatistics statistics;               // all bands: values N·B, parameters B
  std::vector<Residuals> band_residuals;  // per band
  Residuals overall;                      // all bands together
};

// Closed form. Errors: no observations, a covariance that cannot be factored
// (kFailedPrecondition).
Result<LambertFit> FitLambert(const Observations& data);

enum class ParameterSharing { kSharedAcrossBands, kPerBand };
const char* ParameterSharingName(ParameterSharing s);  // "shared", "per_band"

struct CookTorranceOptions {
  ParameterSharing sharing = ParameterSharing::kSharedAcrossBands;
  // Nelder-Mead starts (the best result wins); F0 starts at f0_start for each.
  std::vector<double> alpha_starts = {0.05, 0.15, 0.4};
  double f0_start = 0.04;
  int max_evaluations = 1500;  // per start (and per band when per band)
  // Called with the fraction done (0…1) from the calling thread; may be empty.
  std::function<void(double)> progress;
};

struct CookTorranceFit {
  WavelengthGrid grid;
  ParameterSharing sharing = ParameterSharing::kSharedAcrossBands;
  std::vector<CookTorranceParams> band;  // per band (α and F0 the same in every band if shared)
  // Standard uncertainties of band's fields (the same α and F0 in every band if shared); NaN for
  // a kd or ks at its bound 0 and where the data do not determine a parameter (statistics.note).
  std::vector<CookTorranceParams> band_u;
  FitStatistics statistics;               // all bands: parameters 2B + 2 (shared) or 4B (per band)
  std::vector<Residuals> band_residuals;  // per band
  Residuals overall;
  int evaluations = 0;     // objective evaluations in all
  bool converged = false;  // every search met its tolerances
};

// Errors: fewer than 3 observations (kFailedPrecondition: three unknowns per band at least), a
// covariance that cannot be factored (kFailedPrecondition),
// options without a start or with a non-positive one (kInvalidArgument), kCancelled / kTimeout
// from `ctx`.
Result<CookTorranceFit> FitCookTorrance(const Observations& data,
                                        const CookTorranceOptions& options, const CallContext& ctx);

// Σ over bands of rᵀV⁻¹r, r the residuals of a per-band model over `data` and V each band's
// covariance (CovariancesOf(data): V = I when the data are unweighted).
double WeightedSumOfSquares(const Observations& data, const std::vector<BandCovariance>& covariance,
                            const std::function<double(std::size_t obs, std::size_t band)>& model);

// Residuals of any per-band model over `data`: model(i, band) is its value at observation i.
Residuals ResidualsOf(const Observations& data, std::size_t band_begin, std::size_t band_end,
                      const std::function<double(std::size_t obs, std::size_t band)>& model);

}  // namespace brdf::fit
