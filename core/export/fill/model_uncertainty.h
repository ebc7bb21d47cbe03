// The uncertainty of the fill chain's model cells (docs/uncertainty.md, "Exports"): where no
// interpolation has a value, the fitted Cook-Torrance model answers, and its error there grows
// with the distance to the readings that support it. A model cell at direction x gets
//
//     u(x, λ) = c(d(x), λ) · ρ(x, λ),
//
// ρ the RMS of the model's residuals at the kModelNeighbours readings nearest x (how well the
// model fits there), d the distance to the nearest reading (ReadingDistance), and c per band
// group and per bin of d fitted from held-out readings: the model fitted again without a fold of
// the readings (a block of incidence angles, ModelFolds) predicts each of them, its residual r
// against c · ρ at the reading's own distance from the rest (the split-conformal rank of
// interpolation_calibration.h, c never smaller for a larger d). A cell farther from every reading
// than any held-out reading was from the rest is not estimated (NaN): nothing measured says how far
// off the model is there. Pure: no I/O.
#pragma once

#include <array>
#include <chrono>
#include <cstddef>
#include <cstdint>
#include <memory>
#include <span>
#include <utility>
#include <vector>

#include "core/call_context.h"
#include "core/fit/fit.h"
#include "core/interp/interpolator.h"
#include "core/pose.h"
#include "core/uncertainty/held_out.h"
#include "core/uncertainty/interpolation_calibration.h"
#include "core/wavelength_grid.h"

namespace brdf::exports {

// Readings whose residuals give a model cell's local scale ρ.
inline constexpr std::size_t kModelNeighbours = 4;
// Folds the model is fitted again without (each at most kMaxHeldOut / kModelFolds readings),
// by blocks of incidence kModelBlockDeg wide: block k = ⌊θi / kModelBlockDeg⌋ goes to fold
// k mod kModelFolds. A fold's readings are predicted across a gap of at least one block, as the
// model cells lie beyond the readings (the interpolation and its fallback answer inside them);
// readings left out one at a time would sit among their neighbours and promise too little.
inline constexpr std::size_t kModelFolds = 8;
inline constexpr double kModelBlockDeg = 10;
// Bins of the held-out readings' distances, one c each (fewer when a bin would hold fewer than
// CalibrationTarget::min_points readings).
inline constexpr int kModelDistanceBins = 3;
// The refits' time limit, all folds together (the demo plan's 87 readings take well under 1 s).
inline constexpr auto kModelCalibrationTimeout = std::chrono::minutes(10);

// The distance between two isotropic directions, in degrees: the incidence angles' difference and
// the great-circle angle between the outgoing directions (θo, φ) and (θo', φ') in quadrature. At
// θo = 0 the azimuth does not count, as it does not for the direction.
double ReadingDistance(const IsoDirection& a, const IsoDirection& b);

// The readings of a sample set (coordinates θi, θo, φ) by distance to a direction. The readings
// are put in square buckets of (θi, θo), about four a bucket, and a query scans the buckets in
// rings around its own, skipping those whose (θi, θo) box is farther than the k-th nearest so far
// (a reading's distance is at least the box's: |Δθi| and, for the outgoing directions' angle,
// |Δθo|). The answer is that of a search over every reading: the k smallest (distance, position)
// pairs, so ties go to the lower position.
// A grid asks for cells next to each other in turn: each thread keeps its last query and its
// k-th distance, and a query starts with that distance plus the step between the two as its
// reach (the distance is a metric, so the k nearest lie within it), which skips most readings
// before any trigonometry. The answer is the same as without it.
class ReadingNeighbours {
 public:
  explicit ReadingNeighbours(const interp::SampleSet& samples);
  // The `k` readings nearest `at` (positions in the set), nearest first (equal distances by
  // position), and their distances.
  void Nearest(const IsoDirection& at, std::size_t k, std::vector<std::size_t>* index,
               std::vector<double>* distance) const;

 private:
  // A direction with what its distances need: cos and sin of θo, and (θo, φ) as a unit vector.
  struct Query {
    IsoDirection at;
    double cos_o = 1, sin_o = 0;
    std::array<double, 3> unit{};
  };
  struct Reading : Query {
    std::size_t index = 0;  // its position in the set
  };
  // The readings of bucket (row r of θi, column c of θo) into *best (the k smallest pairs).
  // Readings farther than `reach` (when finite, and until *best holds k) are skipped.
  void ScanBucket(const Query& q, std::size_t k, double reach, int r, int c,
                  std::vector<std::pair<double, std::size_t>>* best) const;
  // The reach a query at `q` may start with: this thread's last query's k-th distance plus the
  // distance from it to `q`; infinite when the last query was of another set or another k.
  double WarmReach(const Query& q, std::size_t k) const;
  // Keeps `q` and its k-th nearest distance `kth` (infinite: fewer than k) for WarmReach.
  void RememberQuery(const Query& q, std::size_t k, double kth) const;

  // This set's number, unique in the process: a thread's last query is kept under it (never
  // under an address another set could reuse).
  std::uint64_t serial_ = 0;
  std::vector<Reading> readings_;       // bucket by bucket
  std::vector<std::size_t> start_;      // bucket b's: readings_[start_[b] .. start_[b + 1])
  double theta_i0_ = 0, theta_o0_ = 0;  // the buckets' lower corner, degrees
  double width_ = 1;                    // a bucket's side, degrees
  int rows_ = 1, columns_ = 1;          // buckets along θi and along θo
};

// The model's residual (model − reading) at every reading of `samples`, per band.
std::vector<std::vector<double>> ModelResiduals(const fit::CookTorranceFit& model,
                                                const interp::SampleSet& samples);

// The model's folds (ModelFolds: blocks of incidence, in hash order within a block, each fold at
// most kMaxHeldOut / kModelFolds readings; empty folds left out).
std::vector<std::vector<std::size_t>> ModelFolds(const interp::SampleSet& samples);

// The model's held-out points: each fold's readings predicted by the model fitted to the others,
// with ρ (spread) and the distance to the nearest reading outside the fold (cell_size). No noise:
// the residual keeps the held-out reading's own noise, which stands in for the measurement part a
// model cell does not have (without it a model within the readings' noise would get u = 0). Folds
// by a hash of the reading ids (uncertainty::HeldOutOrder). A fold whose fit fails gives none.
std::vector<uncertainty::HeldOutPoint> PredictModelHeldOut(const interp::SampleSet& samples,
                                                           const WavelengthGrid& grid,
                                                           const CallContext& ctx);

// The calibration of model cells' u over `samples` (the readings the model was fitted to):
// PredictModelHeldOut fitted with kModelDistanceBins bins of distance, not estimated beyond the
// largest held-out distance. Not calibrated (detail says why) with fewer than min_points points.
uncertainty::InterpolationCalibration CalibrateModel(const interp::SampleSet& samples,
                                                     const WavelengthGrid& grid,
                                                     const CallContext& ctx);

// A model cell's u per band into `u`: c(d) · ρ as above; NaN in every band when the calibration
// has no scale or the cell is farther from every reading than it reaches.
class ModelCellUncertainty {
 public:
  // `samples` must outlive it; `residuals` as ModelResiduals gives them for `samples`.
  ModelCellUncertainty(const interp::SampleSet& samples,
                       std::shared_ptr<const std::vector<std::vector<double>>> residuals,
                       uncertainty::InterpolationCalibration calibration);
  void At(const IsoDirection& at, std::span<double> u) const;
  const uncertainty::InterpolationCalibration& calibration() const { return calibration_; }

 private:
  std::shared_ptr<const ReadingNeighbours> neighbours_;
  std::shared_ptr<const std::vector<std::vector<double>>> residuals_;
  uncertainty::InterpolationCalibration calibration_;
};

}  // namespace brdf::exports
