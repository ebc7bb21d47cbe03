// What a model is fitted to: BRDF spectra (sr⁻¹) measured at isotropic directions (θi, θo, φ),
// all on one wavelength grid, each spectrum optionally with its standard uncertainty per band
// (the reading's budget, docs/uncertainty.md). Built from a session's sample readings
// (core/export's DeriveSamples with the BRDF quantity, or a readings CSV with u columns) or, in
// tests, from a model itself. A fit weights by 1/u² only when every spectrum carries its
// uncertainty (weighted()); otherwise every value counts alike, as before uncertainties existed.
// Pure.
#pragma once

#include <cstddef>
#include <span>
#include <vector>

#include "core/pose.h"
#include "core/status.h"
#include "core/wavelength_grid.h"

namespace brdf::fit {

class Observations {
 public:
  explicit Observations(WavelengthGrid grid) : grid_(grid) {}

  // Appends one spectrum (grid().count values, finite) at `at` (θi, θo in [0°, 90°], φ in
  // [0°, 180°]). kInvalidArgument naming the field otherwise.
  // `u`: the values' standard uncertainties (k = 1, sr⁻¹), grid().count finite values > 0, or
  // empty when the reading has none (not estimated).
  Status Add(const IsoDirection& at, std::span<const double> brdf, std::span<const double> u = {});

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
  // Spectra added with their uncertainties; weighted(): all of them (and at least one).
  std::size_t with_uncertainty() const { return with_uncertainty_; }
  bool weighted() const { return size() > 0 && with_uncertainty_ == size(); }

 private:
  WavelengthGrid grid_;
  std::vector<IsoDirection> directions_;
  std::vector<double> values_;         // size() × bands(), spectrum by spectrum
  std::vector<double> uncertainties_;  // the same layout; NaN where not given
  std::size_t with_uncertainty_ = 0;
};

}  // namespace brdf::fit
