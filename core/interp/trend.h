// A smooth trend under the interpolation: the bivariate approximation of an isotropic BRDF.
//
// Isotropic BRDFs are close to functions of two angles, the half angle θh and the difference angle
// θd (Rusinkiewicz's coordinates, half_difference.h): the microfacet distribution depends on θh,
// Fresnel on θd, and only shadowing and the cosine terms bring in the rest (Romeiro, Vasilyev and
// Zickler, "Passive Reflectometry", ECCV 2008, fit MERL's isotropic materials that way). A sharp
// specular lobe is a function of θh alone, and every sample near the lobe tells about it, whatever
// its θd and φd: a one- or two-dimensional curve is estimated far better from 2,000 scattered
// samples than a three-dimensional one.
//
// BivariateTrend fits, band by band, by least squares over every sample,
//   T(θh, θd) = A(θh, θd) + B(θh, θd) / (cos θi cos θo),
// A and B piecewise bilinear on a fixed grid of knots (θh: 1° apart up to 16°, then wider up to
// 90°; θd: 5° apart), with a light penalty on their second differences that continues the slopes
// into knots no sample reaches (and costs nothing for a trend linear in the angles); B is also
// pulled gently toward 0, so that it takes only what A cannot. A carries a diffuse base and a lobe
// that is a function of θh (Blinn-Phong); B a microfacet lobe D · F · G / 4 divided by the
// foreshortening, which rises toward grazing angles where A alone would need every knot. The
// unknowns are interleaved (A and B at each knot), so the normal equations are banded and solved
// by a banded Cholesky: about 30 ms for 2,000 samples of 101 bands.
// With Options.trend = kBivariate (MakeInterpolator), a method interpolates the residuals
// r_k = f_k − T(x_k) instead of the spectra and adds T at the query:
//   f(q) = T(q) + Σ w_k · r_k.
// Where the BRDF is close to the trend the residuals are small and smooth, and so is the method's
// error; where it is not, the method interpolates what the trend leaves. At a sample's own
// direction nearest neighbour gives the sample back. The answer's vertices and weights are the
// method's own (over the residuals); its detail names the trend.
// Isotropic (3D) data only. Pure: no I/O.
#pragma once

#include <memory>
#include <span>
#include <vector>

#include "core/interp/interpolator.h"
#include "core/status.h"

namespace brdf::interp {

class BivariateTrend {
 public:
  // Fits the trend to every sample of `samples` (3D: (θi, θo, φ), degrees). Errors: data that is
  // not 3D, an empty set (kInvalidArgument / kFailedPrecondition naming what).
  static Result<BivariateTrend> Fit(const SampleSet& samples);

  // T at the isotropic direction `iso` = (θi, θo, φ), one value per band, into `out`
  // (bands() values).
  void At(std::span<const double> iso, std::span<double> out) const;

  int bands() const { return bands_; }
  const std::vector<double>& theta_h_knots() const { return knots_h_; }
  const std::vector<double>& theta_d_knots() const { return knots_d_; }
  // Heap of the knots and the fitted values.
  std::size_t HeapBytes() const {
    return (knots_h_.capacity() + knots_d_.capacity() + values_.capacity()) * sizeof(double);
  }

 private:
  BivariateTrend() = default;

  int bands_ = 0;
  std::vector<double> knots_h_, knots_d_;
  std::vector<double> values_;  // (h knot × d knots + d knot) × bands
};

// `samples` less the trend at their own directions (same ids, coordinates and order).
std::shared_ptr<SampleSet> TrendResiduals(const SampleSet& samples, const BivariateTrend& trend);

// The method `method` over the residuals of `samples` from their fitted trend (options.trend is
// ignored for the inner method), answering f = T + interpolated residual. Errors: as
// MakeInterpolator and BivariateTrend::Fit.
Result<std::unique_ptr<Interpolator>> MakeTrendInterpolator(
    Method method, std::shared_ptr<const SampleSet> samples, const Options& options);

}  // namespace brdf::interp
