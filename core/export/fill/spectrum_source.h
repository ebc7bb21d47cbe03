// Where a resampled export (regular grid, MERL table) gets its spectra: anything that answers a
// spectrum at an isotropic direction (θi, θo, φ). In brdfd that is the session's interpolator; in
// tests and the synthetic demo, a known analytic BRDF.
#pragma once

#include <concepts>
#include <functional>
#include <span>
#include <type_traits>
#include <utility>

#include "core/analytic_brdf.h"
#include "core/interp/interpolator.h"
#include "core/pose.h"
#include "core/wavelength_grid.h"

namespace brdf::exports {

// Answers one direction, or many at once. Called from many threads at once: must be thread-safe.
class SpectrumSource {
 public:
  // Writes one value per band into `out` (out.size() = bands) and returns kOk, or returns why
  // there is no value (and leaves `out` alone).
  using One = std::function<interp::InterpStatus(const IsoDirection& at, std::span<double> out)>;
  // n = statuses.size() directions, row-major (θi, θo, φ) in `directions`; statuses[i] and row i
  // of `spectra` (n × bands values) as One would give them, except that a row whose status is not
  // kOk holds NaN. Interpolator::SpectraAt's contract: what lets a 3D octant interpolator sort a
  // large batch by cell (core/interp/octant/octant.h) instead of answering query by query.
  using Many =
      std::function<void(std::span<const double> directions,
                         std::span<interp::InterpStatus> statuses, std::span<double> spectra)>;

  // From a callable answering one direction (a lambda, a One); Spectra then asks it one by one.
  template <typename F>
  requires(
      !std::same_as<std::remove_cvref_t<F>, SpectrumSource> &&
      std::is_invocable_r_v<interp::InterpStatus, const F&, const IsoDirection&, std::span<double>>)
      SpectrumSource(F one)
      : one_(std::move(one)) {}  // NOLINT(google-explicit-constructor)
  SpectrumSource(One one, Many many) : one_(std::move(one)), many_(std::move(many)) {}

  interp::InterpStatus operator()(const IsoDirection& at, std::span<double> out) const {
    return one_(at, out);
  }
  // Many's contract; directions.size() == 3 × statuses.size(), spectra.size() a multiple of it.
  void Spectra(std::span<const double> directions, std::span<interp::InterpStatus> statuses,
               std::span<double> spectra) const;
  // True when the source has no batch path: Spectra asks One direction by direction, so a caller
  // filling scattered rows may as well ask One on each row where it lies.
  bool one_by_one() const { return !many_; }

 private:
  One one_;
  Many many_;  // empty: one by one through one_
};

// Asks a 3D interpolator: one direction by SpectrumAt, many by SpectraAt (the sorted batch path
// of the octant method). The interpolator must outlive the source.
SpectrumSource InterpolatorSource(const interp::Interpolator& interpolator);

// Evaluates an analytic BRDF (sr⁻¹) on `grid` at CanonicalDirections(at); always kOk.
SpectrumSource AnalyticSource(const AnalyticBrdf& brdf, const WavelengthGrid& grid);

}  // namespace brdf::exports
