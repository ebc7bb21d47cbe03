// The covariance of one band's values over all observations of a fit, and products with its
// inverse (docs/uncertainty.md, "Fits"):
//   V = D + Σ_s b_s b_sᵀ
// D diagonal: each value's independent variance (u² for a value whose u is all independent; 1 for
// every value when the data are unweighted); b_s: shared source s's signed contributions, one per
// observation, 0 for an observation without s (observations.h). By the Woodbury identity
//   V⁻¹ = D⁻¹ − D⁻¹ B M⁻¹ Bᵀ D⁻¹,   M = I + Bᵀ D⁻¹ B   (k × k, k the band's shared sources),
// so xᵀV⁻¹y costs one pass over the observations' shared terms and a k × k triangular solve: no
// n × n matrix is formed. Deterministic and pure.
#pragma once

#include <cstddef>
#include <span>
#include <vector>

#include "core/fit/observations.h"
#include "core/status.h"

namespace brdf::fit {

// A shared source that is a scale of every value: named by every observation, its contributions
// in each band one fraction of the values (the white standard's, f · u(ρw)/ρw). It moves a whole
// band as the models' linear parameters do (kd and ks together; ρ), so it cannot show in the
// residuals; in V, with contributions taken at the measured values, it would let a model far from
// the data shrink toward 0 at a cost of only 1/fraction² per band (Peelle's puzzle). The fits
// leave it out of V and add it to those parameters' uncertainties instead.
struct ScaleSource {
  std::size_t source = 0;        // in data.shared_sources()
  std::vector<double> fraction;  // per band: contribution / value
};
std::vector<ScaleSource> ScaleSourcesOf(const Observations& data);

class BandCovariance {
 public:
  // V of `band` for `data` (unweighted data: V = I), without the sources in `leave_out`.
  // kFailedPrecondition when M cannot be factored (contributions so large or small that it is
  // not numerically positive definite).
  static Result<BandCovariance> Of(const Observations& data, std::size_t band,
                                   const std::vector<ScaleSource>& leave_out = {});

  std::size_t size() const { return inv_d_.size(); }  // observations
  std::size_t shared_sources() const { return k_; }   // sources with a contribution in the band
  // Both diagonal (no shared source) with the same D, as every band of unweighted data (V = I):
  // then Solve and Product answer the same for the same inputs, to the bit.
  bool SameDiagonal(const BandCovariance& other) const {
    return k_ == 0 && other.k_ == 0 && inv_d_ == other.inv_d_;
  }

  // V⁻¹ y for y one value per observation.
  std::vector<double> Solve(std::span<const double> y) const;
  // xᵀ V⁻¹ y.
  double Product(std::span<const double> x, std::span<const double> y) const;
  // The m × m matrix (row-major) of cᵢᵀ V⁻¹ cⱼ over `columns` (each one value per observation).
  std::vector<double> Gram(std::span<const std::vector<double>> columns) const;

 private:
  struct Entry {
    std::size_t column = 0;  // the source's column in B
    double value = 0;        // its contribution
  };
  BandCovariance() = default;
  // z = L⁻¹ Bᵀ D⁻¹ x (k values), so that xᵀV⁻¹y = Σ xᵢyᵢ/Dᵢ − z(x)·z(y).
  std::vector<double> Project(std::span<const double> x) const;

  std::vector<double> inv_d_;         // 1 / Dᵢ
  std::vector<std::size_t> offsets_;  // observation i's entries: [offsets_[i], offsets_[i + 1])
  std::vector<Entry> entries_;
  std::size_t k_ = 0;
  std::vector<double> chol_;  // L of M = L Lᵀ, k × k
};

// One BandCovariance per band of `data` without the sources in `leave_out`, and their errors
// naming the band.
Result<std::vector<BandCovariance>> CovariancesOf(const Observations& data,
                                                  const std::vector<ScaleSource>& leave_out = {});

}  // namespace brdf::fit
