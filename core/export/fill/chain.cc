#include "core/export/fill/chain.h"

#include <algorithm>
#include <cstdio>
#include <limits>

#include "core/fit/models.h"

namespace brdf::exports {

const char* FillPolicyName(FillPolicy p) {
  return p == FillPolicy::kChain ? "chain" : "none";
}

Result<FillPolicy> ParseFillPolicy(const std::string& name) {
  if (name == "none") return FillPolicy::kNone;
  if (name == "chain") return FillPolicy::kChain;
  return InvalidArgument("fill policy '" + name +
                         "': use none (the chosen method alone, holes stay NaN / −1) or chain "
                         "(the method, then Delaunay, then the fitted model)");
}

const char* ProvenanceName(Provenance p) {
  switch (p) {
    case Provenance::kInterpolated:
      return "interpolated";
    case Provenance::kFallback:
      return "fallback";
    case Provenance::kModel:
      return "model";
  }
  return "?";
}

double FillTally::model_fraction() const {
  const std::size_t n = asked();
  return n == 0 ? 0.0 : static_cast<double>(model) / static_cast<double>(n);
}

std::string FillTally::Summary() const {
  char percent[32];
  std::snprintf(percent, sizeof percent, "%.3f %%", 100 * model_fraction());
  return std::string(FillPolicyName(policy)) + ": " + std::to_string(interpolated) +
         " interpolated, " + std::to_string(fallback) + " fallback, " + std::to_string(model) +
         " model (" + percent + "), " + std::to_string(empty) + " empty";
}

std::string FillTally::Json() const {
  char fraction[32];
  std::snprintf(fraction, sizeof fraction, "%.6g", model_fraction());
  return std::string("{\"policy\": \"") + FillPolicyName(policy) +
         "\", \"interpolated\": " + std::to_string(interpolated) +
         ", \"fallback\": " + std::to_string(fallback) + ", \"model\": " + std::to_string(model) +
         ", \"empty\": " + std::to_string(empty) + ", \"model_fraction\": " + fraction + "}";
}

FillChain::FillChain(FillPolicy policy, std::vector<Stage> stages)
    : policy_(policy), stages_(std::move(stages)), counters_(std::make_unique<Counters>()) {
  if (policy_ == FillPolicy::kNone && stages_.size() > 1) {
    stages_.erase(stages_.begin() + 1, stages_.end());
  }
}

void FillChain::Count(std::size_t stage_or_empty, std::size_t n) const {
  if (n == 0) return;
  if (stage_or_empty >= stages_.size()) {
    counters_->empty += n;
    return;
  }
  switch (stages_[stage_or_empty].provenance) {
    case Provenance::kInterpolated:
      counters_->interpolated += n;
      break;
    case Provenance::kFallback:
      counters_->fallback += n;
      break;
    case Provenance::kModel:
      counters_->model += n;
      break;
  }
}

interp::InterpStatus FillChain::AnswerOne(const IsoDirection& at, std::span<double> out) const {
  interp::InterpStatus first = interp::InterpStatus::kOutsideHull;
  for (std::size_t s = 0; s < stages_.size(); ++s) {
    const interp::InterpStatus st = stages_[s].source(at, out);
    if (s == 0) first = st;
    if (st == interp::InterpStatus::kOk) {
      Count(s, 1);
      return st;
    }
  }
  Count(stages_.size(), 1);
  return first;
}

std::unique_ptr<FillChain::Scratch> FillChain::TakeScratch() const {
  MutexLock lock(scratch_mu_);
  if (scratch_.empty()) return std::make_unique<Scratch>();
  std::unique_ptr<Scratch> taken = std::move(scratch_.back());
  scratch_.pop_back();
  return taken;
}

void FillChain::GiveScratch(std::unique_ptr<Scratch> scratch) const {
  MutexLock lock(scratch_mu_);
  scratch_.push_back(std::move(scratch));
}

void FillChain::AnswerInPlace(const SpectrumSource& source, std::span<const double> directions,
                              std::span<interp::InterpStatus> statuses, std::span<double> spectra,
                              std::size_t bands, const std::vector<std::size_t>& missing,
                              std::vector<std::size_t>& still) {
  still.clear();
  for (const std::size_t i : missing) {
    const std::span<double> row = spectra.subspan(i * bands, bands);
    const IsoDirection at{directions[3 * i], directions[3 * i + 1], directions[3 * i + 2]};
    if (source(at, row) == interp::InterpStatus::kOk) {
      statuses[i] = interp::InterpStatus::kOk;
    } else {
      // As if it had not been asked: the row stays NaN with the first stage's status.
      std::fill(row.begin(), row.end(), std::numeric_limits<double>::quiet_NaN());
      still.push_back(i);
    }
  }
}

void FillChain::AnswerMany(std::span<const double> directions,
                           std::span<interp::InterpStatus> statuses,
                           std::span<double> spectra) const {
  const std::size_t n = statuses.size();
  if (n == 0) return;
  const std::size_t bands = spectra.size() / n;
  stages_.front().source.Spectra(directions, statuses, spectra);
  std::unique_ptr<Scratch> scratch = TakeScratch();
  std::vector<std::size_t>& missing = scratch->missing;
  missing.clear();
  for (std::size_t i = 0; i < n; ++i) {
    if (statuses[i] != interp::InterpStatus::kOk) missing.push_back(i);
  }
  Count(0, n - missing.size());
  std::vector<double>& dirs = scratch->directions;
  std::vector<interp::InterpStatus>& sub_status = scratch->statuses;
  std::vector<double>& sub_spectra = scratch->spectra;
  std::vector<std::size_t>& still = scratch->still;
  for (std::size_t s = 1; s < stages_.size() && !missing.empty(); ++s) {
    if (stages_[s].source.one_by_one()) {
      AnswerInPlace(stages_[s].source, directions, statuses, spectra, bands, missing, still);
      Count(s, missing.size() - still.size());
      missing.swap(still);
      continue;
    }
    dirs.clear();
    for (std::size_t i : missing) {
      dirs.insert(dirs.end(), directions.begin() + static_cast<std::ptrdiff_t>(3 * i),
                  directions.begin() + static_cast<std::ptrdiff_t>(3 * i + 3));
    }
    sub_status.assign(missing.size(), interp::InterpStatus::kOk);
    // Not cleared: the stage writes every row it answers (and NaN in the others), and only rows
    // it answered are copied out.
    sub_spectra.resize(missing.size() * bands);
    stages_[s].source.Spectra(dirs, sub_status, sub_spectra);
    still.clear();
    for (std::size_t q = 0; q < missing.size(); ++q) {
      const std::size_t i = missing[q];
      if (sub_status[q] != interp::InterpStatus::kOk) {
        still.push_back(i);
        continue;
      }
      statuses[i] = interp::InterpStatus::kOk;
      std::copy_n(sub_spectra.begin() + static_cast<std::ptrdiff_t>(q * bands), bands,
                  spectra.begin() + static_cast<std::ptrdiff_t>(i * bands));
    }
    Count(s, missing.size() - still.size());
    missing.swap(still);
  }
  // Rows no stage answered: NaN with the first stage's status (a stage need not have written
  // them, FillChain::Stage).
  for (const std::size_t i : missing) {
    std::fill_n(spectra.begin() + static_cast<std::ptrdiff_t>(i * bands), bands,
                std::numeric_limits<double>::quiet_NaN());
  }
  Count(stages_.size(), missing.size());
  GiveScratch(std::move(scratch));
}

SpectrumSource FillChain::Source() const {
  return SpectrumSource(
      [this](const IsoDirection& at, std::span<double> out) { return AnswerOne(at, out); },
      [this](std::span<const double> directions, std::span<interp::InterpStatus> statuses,
             std::span<double> spectra) { AnswerMany(directions, statuses, spectra); });
}

FillTally FillChain::Tally() const {
  FillTally t;
  t.policy = policy_;
  t.interpolated = counters_->interpolated.load();
  t.fallback = counters_->fallback.load();
  t.model = counters_->model.load();
  t.empty = counters_->empty.load();
  return t;
}

SpectrumSource ModelSource(const fit::CookTorranceFit& model) {
  return [params = model.band](const IsoDirection& at, std::span<double> out) {
    fit::CookTorranceSpectrumAt(fit::LobeGeometryOf(at), params, out);
    return interp::InterpStatus::kOk;
  };
}

}  // namespace brdf::exports
