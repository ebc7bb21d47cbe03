#include "core/export/fill/model_uncertainty.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <numbers>
#include <utility>

#include "core/export/fill/session_interpolant.h"
#include "core/fit/models.h"
#include "core/fit/observations.h"

namespace brdf::exports {
namespace {

constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();
constexpr double kRadian = std::numbers::pi / 180.0;

IsoDirection At(const interp::SampleSet& samples, std::size_t i) {
  const std::span<const double> c = samples.coords(i);
  return {c[0], c[1], c[2]};
}

// ρ per band: the RMS of `residuals` over the readings `near`.
void LocalScale(const std::vector<std::vector<double>>& residuals,
                std::span<const std::size_t> near, std::span<double> rho) {
  std::fill(rho.begin(), rho.end(), 0.0);
  for (const std::size_t i : near) {
    for (std::size_t b = 0; b < rho.size() && b < residuals[i].size(); ++b) {
      rho[b] += residuals[i][b] * residuals[i][b];
    }
  }
  const double n = static_cast<double>(std::max<std::size_t>(1, near.size()));
  for (double& r : rho) r = std::sqrt(r / n);
}

// The readings of `samples` outside `held` (a fold), as a set of their own, and their positions.
std::shared_ptr<interp::SampleSet> Rest(const interp::SampleSet& samples,
                                        std::span<const std::size_t> held,
                                        std::vector<std::size_t>* rest_to_all) {
  std::vector<bool> is_held(samples.size(), false);
  for (const std::size_t j : held) is_held[j] = true;
  auto rest = std::make_shared<interp::SampleSet>(samples.dims(), samples.bands());
  for (std::size_t i = 0; i < samples.size(); ++i) {
    if (is_held[i] || !rest->Add(samples.id(i), samples.coords(i), samples.spectrum(i)).ok()) {
      continue;
    }
    rest_to_all->push_back(i);
  }
  return rest;
}

// The model fitted to `rest` as FitSampleModel fits a session's (the same subsample rule); an
// error when the fit fails.
Result<fit::CookTorranceFit> FitRest(const interp::SampleSet& rest, const WavelengthGrid& grid,
                                     const CallContext& ctx) {
  fit::Observations data(grid);
  for (const std::size_t i : ModelFitSamples(rest.size())) {
    if (Status st = data.Add(At(rest, i), rest.spectrum(i)); !st.ok()) return st;
  }
  return fit::FitCookTorrance(data, {}, ctx);
}

// One fold's points: the model fitted without `held`, each held reading predicted.
void PredictModelFold(const interp::SampleSet& samples, std::span<const std::size_t> held,
                      const WavelengthGrid& grid, const CallContext& ctx,
                      std::vector<uncertainty::HeldOutPoint>* out) {
  std::vector<std::size_t> rest_to_all;
  const std::shared_ptr<interp::SampleSet> rest = Rest(samples, held, &rest_to_all);
  if (rest->size() < kModelNeighbours) return;
  Result<fit::CookTorranceFit> model = FitRest(*rest, grid, ctx);
  if (!model.ok()) return;
  const std::vector<std::vector<double>> residuals = ModelResiduals(*model, *rest);
  const ReadingNeighbours neighbours(*rest);
  std::vector<std::size_t> near;
  std::vector<double> distance;
  for (const std::size_t j : held) {
    const IsoDirection at = At(samples, j);
    const std::span<const double> f = samples.spectrum(j);
    uncertainty::HeldOutPoint p;
    p.residual.resize(f.size());
    for (std::size_t b = 0; b < f.size() && b < model->band.size(); ++b) {
      p.residual[b] = fit::CookTorranceBrdf(at, model->band[b]) - f[b];
    }
    neighbours.Nearest(at, kModelNeighbours, &near, &distance);
    p.spread.resize(f.size());
    LocalScale(residuals, near, p.spread);
    p.cell_size = distance.empty() ? 0.0 : distance.front();
    out->push_back(std::move(p));
  }
}

}  // namespace

double ReadingDistance(const IsoDirection& a, const IsoDirection& b) {
  const double to = a.theta_o * kRadian, to2 = b.theta_o * kRadian;
  const double cos_gamma = std::cos(to) * std::cos(to2) +
                           std::sin(to) * std::sin(to2) * std::cos((a.phi - b.phi) * kRadian);
  const double gamma = std::acos(std::clamp(cos_gamma, -1.0, 1.0)) / kRadian;
  return std::hypot(a.theta_i - b.theta_i, gamma);
}

ReadingNeighbours::ReadingNeighbours(const interp::SampleSet& samples) {
  index_.resize(samples.size());
  for (std::size_t i = 0; i < index_.size(); ++i) index_[i] = i;
  std::sort(index_.begin(), index_.end(), [&samples](std::size_t x, std::size_t y) {
    return samples.coords(x)[0] < samples.coords(y)[0];
  });
  at_.reserve(index_.size());
  for (const std::size_t i : index_) at_.push_back(At(samples, i));
}

void ReadingNeighbours::Nearest(const IsoDirection& at, std::size_t k,
                                std::vector<std::size_t>* index,
                                std::vector<double>* distance) const {
  // Outward from `at`'s θi in both directions; a reading whose θi alone is farther than the k-th
  // nearest so far ends that direction (the distance is at least |Δθi|).
  std::vector<std::pair<double, std::size_t>> best;
  auto consider = [&](std::size_t s) {
    best.emplace_back(ReadingDistance(at, at_[s]), index_[s]);
    std::sort(best.begin(), best.end());
    if (best.size() > k) best.pop_back();
  };
  auto bound = [&] {
    return best.size() < k ? std::numeric_limits<double>::infinity() : best.back().first;
  };
  const auto mid = std::lower_bound(at_.begin(), at_.end(), at.theta_i,
                                    [](const IsoDirection& d, double t) { return d.theta_i < t; });
  for (auto it = mid; it != at_.end() && it->theta_i - at.theta_i <= bound(); ++it) {
    consider(static_cast<std::size_t>(it - at_.begin()));
  }
  for (auto it = mid; it != at_.begin() && at.theta_i - std::prev(it)->theta_i <= bound(); --it) {
    consider(static_cast<std::size_t>(std::prev(it) - at_.begin()));
  }
  index->clear();
  distance->clear();
  for (const auto& [d, i] : best) {
    distance->push_back(d);
    index->push_back(i);
  }
}

std::vector<std::vector<double>> ModelResiduals(const fit::CookTorranceFit& model,
                                                const interp::SampleSet& samples) {
  std::vector<std::vector<double>> out(samples.size());
  for (std::size_t i = 0; i < samples.size(); ++i) {
    const IsoDirection at = At(samples, i);
    const std::span<const double> f = samples.spectrum(i);
    out[i].assign(f.size(), 0.0);
    for (std::size_t b = 0; b < f.size() && b < model.band.size(); ++b) {
      out[i][b] = fit::CookTorranceBrdf(at, model.band[b]) - f[b];
    }
  }
  return out;
}

std::vector<std::vector<std::size_t>> ModelFolds(const interp::SampleSet& samples) {
  std::vector<std::vector<std::size_t>> folds(kModelFolds);
  const std::size_t most = uncertainty::kMaxHeldOut / kModelFolds;
  for (const std::size_t i : uncertainty::HeldOutOrder(samples)) {
    const double block = std::floor(samples.coords(i)[0] / kModelBlockDeg);
    const std::size_t f = static_cast<std::size_t>(std::max(0.0, block)) % kModelFolds;
    if (folds[f].size() < most) folds[f].push_back(i);
  }
  std::erase_if(folds, [](const std::vector<std::size_t>& f) { return f.empty(); });
  return folds;
}

std::vector<uncertainty::HeldOutPoint> PredictModelHeldOut(const interp::SampleSet& samples,
                                                           const WavelengthGrid& grid,
                                                           const CallContext& ctx) {
  std::vector<uncertainty::HeldOutPoint> out;
  if (samples.size() < 2) return out;
  for (const std::vector<std::size_t>& fold : ModelFolds(samples)) {
    if (fold.size() < samples.size()) PredictModelFold(samples, fold, grid, ctx, &out);
  }
  return out;
}

uncertainty::InterpolationCalibration CalibrateModel(const interp::SampleSet& samples,
                                                     const WavelengthGrid& grid,
                                                     const CallContext& ctx) {
  uncertainty::CalibrationTarget target;
  target.size_bins = kModelDistanceBins;
  target.beyond = uncertainty::SizeBeyond::kNotEstimated;
  const std::vector<uncertainty::HeldOutPoint> points = PredictModelHeldOut(samples, grid, ctx);
  return uncertainty::FitInterpolationCalibration(points, static_cast<int>(grid.count), target);
}

ModelCellUncertainty::ModelCellUncertainty(
    const interp::SampleSet& samples,
    std::shared_ptr<const std::vector<std::vector<double>>> residuals,
    uncertainty::InterpolationCalibration calibration)
    : neighbours_(std::make_shared<const ReadingNeighbours>(samples)),
      residuals_(std::move(residuals)),
      calibration_(std::move(calibration)) {}

void ModelCellUncertainty::At(const IsoDirection& at, std::span<double> u) const {
  thread_local std::vector<std::size_t> near;
  thread_local std::vector<double> distance;
  neighbours_->Nearest(at, kModelNeighbours, &near, &distance);
  const double d = distance.empty() ? kNaN : distance.front();
  if (calibration_.scale.size() != u.size() || !std::isfinite(d) ||
      uncertainty::BeyondCalibration(calibration_, d)) {
    std::fill(u.begin(), u.end(), kNaN);
    return;
  }
  LocalScale(*residuals_, near, u);
  for (std::size_t b = 0; b < u.size(); ++b) u[b] *= uncertainty::ScaleAt(calibration_, d, b);
}

}  // namespace brdf::exports
