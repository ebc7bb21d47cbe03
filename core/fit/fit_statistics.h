// How well a weighted least-squares fit explains its data, and how well it pins its parameters
// down (docs/uncertainty.md, "Fits"). With uncertainties (the values' covariance V per band: the
// diagonal of u² when every u is independent, with the shared sources' terms for generalised
// least squares, band_covariance.h):
//   χ² = Σ_bands rᵀ V⁻¹ r,  dof = values − parameters,  χ²/dof ≈ 1 when the model describes the
//   data within their noise; well above 1 when it cannot (a misfit, or understated uncertainties).
// Parameter covariance at the optimum: C = (Jᵀ V⁻¹ J)⁻¹ from the Jacobian J of the model values
// over every fitted parameter. It is NOT scaled by χ²/dof when the data carry uncertainties (they
// are taken as stated, the GUM's propagation; scaling would hide a misfit in wider parameter
// uncertainties); without uncertainties (W = 1) it is scaled by s² = Σ r² / dof, the residuals'
// own variance, the only estimate of the noise there is (ordinary least squares). Pure.
#pragma once

#include <cstddef>
#include <string>
#include <vector>

#include "core/fit/observations.h"

namespace brdf::fit {

struct FitStatistics {
  bool weighted = false;  // weighted by the data's uncertainties; false: all alike
  Weighting weighting = Weighting::kUnweighted;  // how (kUnweighted exactly when !weighted)
  std::size_t shared_terms = 0;                  // the shared sources named (kGeneralised)
  // Of those, scales of every value (band_covariance.h's ScaleSource): left out of V and added
  // to the linear parameters' uncertainties (kd, ks; ρ).
  std::size_t scale_terms = 0;
  std::size_t values = 0;          // values fitted
  std::size_t parameters = 0;      // parameters fitted
  double chi2 = 0;                 // Σ rᵀV⁻¹r (weighted); Σ r² in sr⁻² (unweighted)
  double dof = 0;                  // values − parameters
  double chi2_per_dof = 0;         // χ²/dof; NaN when unweighted (no noise to compare with)
  bool covariance_scaled = false;  // C scaled by Σ r² / dof (only when unweighted)
  std::string note;                // why a parameter's uncertainty is missing, or ""
};

// χ², dof and χ²/dof from the weighted sum of squared residuals (or the plain one, unweighted),
// for `data`'s weighting.
FitStatistics StatisticsOf(const Observations& data, double sum_of_squares, std::size_t values,
                           std::size_t parameters);

// The Cholesky factor L (lower triangle, row-major, zeros above) of a symmetric positive-definite
// n × n matrix a = L Lᵀ; empty when a is not positive definite.
std::vector<double> CholeskyLower(std::vector<double> a, std::size_t n);

// The inverse of a symmetric positive-definite n × n matrix (row-major), by Cholesky; empty when
// it is not positive definite (a parameter the data do not determine).
std::vector<double> InvertSymmetric(std::vector<double> a, std::size_t n);

// The diagonal of InvertSymmetric(a, n), the same values to the bit (zeros aside, whose sign
// may differ), in far fewer operations for a sparse a (each row's entries before its first
// non-zero are skipped: the fits' normal matrices, a 2 × 2 block per band and two shared rows,
// cost about n² instead of n³/2); empty when a is not positive definite.
std::vector<double> InverseDiagonal(std::vector<double> a, std::size_t n);

// Standard uncertainties √Cₖₖ of the parameters whose normal-matrix row `free[k]` is true, from
// the normal matrix JᵀV⁻¹J (n × n, row-major); NaN for the others and for all of them when the
// free block is singular (stats.note says so). Scales by Σ r² / dof when stats is unweighted.
std::vector<double> ParameterUncertainties(const std::vector<double>& normal, std::size_t n,
                                           const std::vector<bool>& free, FitStatistics& stats);

}  // namespace brdf::fit
