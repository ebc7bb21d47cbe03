// What a model is fitted to: BRDF spectra (sr⁻¹) measured at isotropic directions (θi, θo, φ),
// all on one wavelength grid. Built from a session's sample readings (core/export's
// DeriveSamples with the BRDF quantity) or, in tests, from a model itself. Pure.
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
  Status Add(const IsoDirection& at, std::span<const double> brdf);

  const WavelengthGrid& grid() const { return grid_; }
  std::size_t size() const { return directions_.size(); }
  std::size_t bands() const { return grid_.count; }
  const IsoDirection& direction(std::size_t i) const { return directions_[i]; }
  double value(std::size_t i, std::size_t band) const { return values_[i * grid_.count + band]; }
  std::span<const double> spectrum(std::size_t i) const {
    return {values_.data() + i * grid_.count, grid_.count};
  }

 private:
  WavelengthGrid grid_;
  std::vector<IsoDirection> directions_;
  std::vector<double> values_;  // size() × bands(), spectrum by spectrum
};

}  // namespace brdf::fit
