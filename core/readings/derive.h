// Radiance, reflectance and BRDF from a session's readings, one reading at a time: the one
// derivation brdfd has. The daemon's interpolation index folds each committed reading in as it
// lands; the exports and the fits fold a stored session's readings in order (core/export's
// DeriveSamples). Quantities as core/readings/quantity.h defines them.
//
// A reading's quantity cannot be computed when its directions are below the surface (θi or θo
// outside [0°, 90°]), its spectrum is invalid, its wavelength grid differs from the session's
// (that of the first sample reading with valid directions and spectrum), the dark it names is
// unknown or on another grid (no quantity then), it names no known reference (no reflectance, no
// BRDF), the reference is too dark in a band, or the BRDF's cosine ratio is undefined. The reason
// is a sentence that starts with the reading ("reading 12: it names no reference reading"). Pure:
// no I/O.
#pragma once

#include <array>
#include <cstdint>
#include <optional>
#include <string>
#include <unordered_map>
#include <vector>

#include "core/readings/quantity.h"
#include "core/readings/reading.h"
#include "core/spectrum.h"

namespace brdf {

// What one sample reading gives: each quantity's values (one per band of the session's grid),
// or why that quantity cannot be computed.
struct SampleQuantities {
  std::int64_t reading_id = 0;
  Directions directions;
  std::array<std::vector<double>, kQuantityCount> values;  // by Quantity; empty when not
  std::array<std::string, kQuantityCount> why_not;         // by Quantity; "" when values hold it

  bool has(Quantity q) const { return why_not[static_cast<int>(q)].empty(); }
  const std::vector<double>& of(Quantity q) const { return values[static_cast<int>(q)]; }
  const std::string& reason(Quantity q) const { return why_not[static_cast<int>(q)]; }
};

// Keeps the references and darks a session has taken so far, and derives each sample reading
// from the ones it names. Feed it the session's readings in the order they were taken (a sample
// names an earlier reference and dark). Not thread-safe: one owner.
class ReadingDeriver {
 public:
  // ρw: the session's white reflectance (WhiteReflectanceOf). white_spectrum: ρw(λ) from the
  // white standard's certificate (a plan's sample block); when given it replaces the number in
  // the BRDF, linearly interpolated onto the session's grid (a grid reaching outside it gives no
  // BRDF, with the reason).
  explicit ReadingDeriver(double white_reflectance,
                          std::optional<Spectrum> white_spectrum = std::nullopt);

  // Takes the next reading. A reference or dark is kept for the samples that name it (nullopt);
  // a sample comes back with its quantities.
  std::optional<SampleQuantities> Fold(const Reading& reading);

  // The session's wavelength grid: that of the first sample reading with valid directions and
  // spectrum. nullopt until there is one.
  const std::optional<WavelengthGrid>& grid() const { return grid_; }
  double white_reflectance() const { return white_reflectance_; }

 private:
  struct Reference {
    Spectrum spectrum;
    double theta_i = 0;  // incidence at which the white was read (θi,ref)
  };
  SampleQuantities Derive(const Reading& sample);
  // The session's grid from the first sample reading, and ρw(λ) on it (or why not).
  void AdoptGrid(const WavelengthGrid& grid);
  // The sample's dark reading (nullptr when it names none), or why it cannot be used.
  Result<const Spectrum*> DarkOf(const Reading& sample) const;
  // Reflectance and BRDF of a sample whose radiance is in `out`, or why not.
  void DeriveReflectanceAndBrdf(const Reading& sample, const Spectrum* dark,
                                SampleQuantities& out) const;

  double white_reflectance_;
  std::optional<Spectrum> white_spectrum_;
  // white_spectrum_ on the session's grid, or why it cannot be (made with the first sample).
  std::optional<Result<Spectrum>> white_on_grid_;
  std::optional<WavelengthGrid> grid_;
  std::unordered_map<std::int64_t, Reference> references_;
  std::unordered_map<std::int64_t, Spectrum> darks_;
};

}  // namespace brdf
