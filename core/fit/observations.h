// What a model is fitted to: BRDF spectra (sr⁻¹) measured at isotropic directions (θi, θo, φ),
// all on one wavelength grid, each spectrum optionally with its standard uncertainty per band
// (the reading's budget, docs/uncertainty.md). Built from a session's sample readings
// (core/export's DeriveSamples with the BRDF quantity, or a readings CSV with u columns) or, in
// tests, from a model itself. A fit weights by the uncertainties only when every spectrum carries
// them (weighted()); otherwise every value counts alike, as before uncertainties existed.
//
// A spectrum's uncertainty is either one u per band, taken as independent of every other value
// (Add), or split (AddWithSharedTerms) into an independent part and signed contributions of named
// shared sources — an error drawn once and carried by every value that names the same source (the
// session's white standard, a reference reading, the instrument; docs/uncertainty.md, "Shared and
// independent"). Per band, the values' covariance is then V = D + Σ_s b_s b_sᵀ (D: the independent
// variances; b_s: source s's contributions, 0 for the values without it); bands are not
// correlated with each other (the budgets do not carry that). Pure.
#pragma once

#include <cstddef>
#include <map>
#include <span>
#include <string>
#include <vector>

#include "core/pose.h"
#include "core/status.h"
#include "core/wavelength_grid.h"

namespace brdf::fit {

// One shared source's part of a spectrum's uncertainty: the same `source` in several spectra is
// one error, common to all of them.
struct SharedContribution {
  std::string source;                // names the error, e.g. "white_standard@session 3"
  std::vector<double> contribution;  // signed, per band, sr⁻¹ (k = 1); finite
};

// How a fit weighs the values (FitStatistics::weighting).
enum class Weighting {
  kUnweighted,   // some spectrum carries no uncertainty: every value alike
  kIndependent,  // by 1/u², every value's u independent of the others (a diagonal V)
  kGeneralised,  // by V⁻¹, V with the shared sources' covariance (generalised least squares)
};

// One shared source's contribution to spectrum i (the source's index in shared_sources()).
struct SharedTerm {
  std::size_t source = 0;
  std::vector<double> contribution;  // per band
};

class Observations {
 public:
  explicit Observations(WavelengthGrid grid) : grid_(grid) {}

  // Appends one spectrum (grid().count values, finite) at `at` (θi, θo in [0°, 90°], φ in
  // [0°, 180°]). kInvalidArgument naming the field otherwise.
  // `u`: the values' standard uncertainties (k = 1, sr⁻¹), grid().count finite values > 0, or
  // empty when the reading has none (not estimated).
  Status Add(const IsoDirection& at, std::span<const double> brdf, std::span<const double> u = {});

  // Appends one spectrum with its uncertainty split: `independent` (grid().count finite values
  // > 0, sr⁻¹) and the shared sources' contributions (grid().count finite values each; a source
  // named at most once per spectrum). uncertainty(i, b) is then the combined
  // √(independent² + Σ contribution²). kInvalidArgument naming the field otherwise.
  Status AddWithSharedTerms(const IsoDirection& at, std::span<const double> brdf,
                            std::span<const double> independent,
                            std::span<const SharedContribution> shared);

  const WavelengthGrid& grid() const { return grid_; }
  std::size_t size() const { return directions_.size(); }
  std::size_t bands() const { return grid_.count; }
  const IsoDirection& direction(std::size_t i) const { return directions_[i]; }
  double value(std::size_t i, std::size_t band) const { return values_[i * grid_.count + band]; }
  std::span<const double> spectrum(std::size_t i) const {
    return {values_.data() + i * grid_.count, grid_.count};
  }
  // The standard uncertainty of value (i, band); NaN when spectrum i carries none.
  double uncertainty(std::size_t i, std::size_t band) const {
    return uncertainties_[i * grid_.count + band];
  }
  // The independent part of uncertainty(i, band): all of it for a spectrum added with one u.
  double independent_uncertainty(std::size_t i, std::size_t band) const {
    return independent_[i * grid_.count + band];
  }
  // The shared sources' contributions to spectrum i (none for a spectrum added with one u).
  std::span<const SharedTerm> shared(std::size_t i) const { return shared_[i]; }
  // The distinct shared sources named, in the order they first appeared.
  const std::vector<std::string>& shared_sources() const { return source_names_; }
  // Spectra added with their uncertainties; weighted(): all of them (and at least one).
  std::size_t with_uncertainty() const { return with_uncertainty_; }
  bool weighted() const { return size() > 0 && with_uncertainty_ == size(); }
  // kGeneralised when weighted() and some spectrum names a shared source.
  Weighting weighting() const;

 private:
  Status Validate(const std::string& where, const IsoDirection& at, std::span<const double> brdf,
                  std::span<const double> u, const char* what) const;
  void Append(const IsoDirection& at, std::span<const double> brdf,
              std::span<const double> independent, std::vector<SharedTerm> shared);

  WavelengthGrid grid_;
  std::vector<IsoDirection> directions_;
  std::vector<double> values_;                   // size() × bands(), spectrum by spectrum
  std::vector<double> uncertainties_;            // the same layout; NaN where not given
  std::vector<double> independent_;              // the same layout; NaN where not given
  std::vector<std::vector<SharedTerm>> shared_;  // per spectrum
  std::vector<std::string> source_names_;
  std::map<std::string, std::size_t> source_index_;
  std::size_t with_uncertainty_ = 0;
};

// "GLS with N shared terms", "weighted, independent", "unweighted: readings without a budget".
std::string WeightingText(Weighting weighting, std::size_t shared_terms);

}  // namespace brdf::fit
