// The readings so far as the judged method sees them (interpolated_model.h): their scalar BRDF
// over their isotropic points (θi, θo, φ), the judged method's index over them (JudgeOptions()),
// and the interpolation term's scale c fitted from held-out readings. Pure: no I/O.
//
// The scale: readings are put in folds by a fixed hash of their positions in the input (the
// same readings in the same order give the same folds); each fold is left out, an index of the
// same method over the rest predicts each of its readings at its own point, and each answer gives
// a residual r, the spread s of its vertices and the noise n of the residual (the reading's own u
// and its vertices', weighted, in quadrature); c is uncertainty::FitInterpolationCalibration's
// (k = 2, 95 %, split-conformal rank). The folds and predictions are the daemon's own
// (core/uncertainty/held_out.h, PredictHeldOut, over a one-band sample set with each reading's
// u · BRDF as its independent noise): at most 300 readings predicted in at most 32 folds, the
// folds' indexes holding together at most about 60,000 readings (octant) or 10,000 (Delaunay).
// Fewer than 8 predicted: c = 1, `calibrated()` false.
#pragma once

#include <array>
#include <cstddef>
#include <memory>
#include <optional>
#include <span>
#include <vector>

#include "core/adaptive/adaptive_spec.h"
#include "core/adaptive/uncertainty_model.h"
#include "core/interp/interpolator.h"

namespace brdf::adaptive {

// The judged interpolant's answer at one point, with its uncertainty (standard, k = 1, absolute,
// sr⁻¹).
struct JudgedAnswer {
  double value = 0;
  // sqrt(Σ (wᵢ uᵢ fᵢ)²) over the blended readings, their relative u as independent; a reading
  // blended more than once (mirror images) counts once, with its weights summed.
  double u_measurement = 0;
  double u_interpolation = 0;                   // c · s
  std::vector<std::array<double, 3>> vertices;  // where the blended readings are (mirror images
                                                // where the method used one)
};

class JudgedReadings {
 public:
  // Readings with a non-finite direction or BRDF, or a relative u that is negative or not finite,
  // are left out. The judged method's index; when it cannot be built (Delaunay over too few or
  // coplanar points) the octant method's; when neither, none (every Answer is empty).
  JudgedReadings(std::span<const ReadingSoFar> readings, Judge judge);
  ~JudgedReadings();

  // The answer at (θi, θo, φ); empty where the method has none (an empty octant, outside the
  // hull, no index).
  std::optional<JudgedAnswer> Answer(const std::array<double, 3>& point) const;
  // Per orthant about `point` (bit 0: θi ≥, bit 1: θo ≥, bit 2: φ ≥ the point's), the squared
  // distance (degrees², in (θi, θo, φ)) to the nearest usable reading or its mirror image in φ
  // (−φ, 360° − φ, as JudgeOptions() adds them); +∞ for an empty orthant.
  std::array<double, 8> OrthantNearest2(const std::array<double, 3>& point) const;
  // The mean of the usable readings' squared BRDF; 0 without any.
  double MeanSquareValue() const;

  std::size_t usable() const { return relative_u_.size(); }
  double scale() const { return scale_; }
  bool calibrated() const { return calibrated_; }
  std::size_t held_out() const { return held_out_; }

 private:
  std::shared_ptr<interp::SampleSet> samples_;
  std::vector<double> relative_u_;  // per sample
  std::unique_ptr<interp::Interpolator> index_;
  double scale_ = 1;
  bool calibrated_ = false;
  std::size_t held_out_ = 0;
};

}  // namespace brdf::adaptive
