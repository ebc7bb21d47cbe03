// Each sample reading's uncertainty budget (docs/uncertainty.md): estimated as the executor
// commits the reading, from the session's references and darks so far, the plan's averages and
// white standard, and the configured terms (core/uncertainty's EstimateReadingBudget), and
// estimated again when the session's last step is done (EstimateSession), when the whole session
// is known: the pose term through the gradient the neighbouring readings give
// (core/uncertainty/pose_gradient.h) and the lamp drift between the reference before and after.
// At commit the pose stays "not estimated" (no neighbours yet), and the lamp drift too until the
// session has two references or a configured rate.
#pragma once

#include <cstdint>
#include <map>
#include <optional>
#include <utility>
#include <vector>

#include "core/spectrum.h"
#include "core/status.h"
#include "core/uncertainty/budget.h"
#include "core/uncertainty/pose_gradient.h"
#include "daemon/config/config.h"
#include "storage/records.h"

namespace brdf::daemon {

// The daemon-wide terms, from [sample] and [uncertainty].
struct ReadingBudgetSettings {
  uncertainty::BudgetTerms terms;
  double white_reflectance_u = 0;             // [sample] white_reflectance_uncertainty
  std::optional<double> lamp_drift_per_hour;  // used with a single reference
};

// The settings a configuration gives; nullopt when [uncertainty] enabled = false. The stage's
// repeatability per axis adds the resolution of that axis, 1 / counts_per_degree, read as
// rectangular (u = step / √12).
std::optional<ReadingBudgetSettings> ReadingBudgetSettingsFrom(const Config& config);

// One session's budgets. Feed it the session's references and darks in order (Observe), ask for
// each sample's budget (Estimate). Not thread-safe: the executor's.
class ReadingBudgeter {
 public:
  // white_spectrum: the plan's ρw(λ), else nullopt and `white_reflectance` for every band;
  // white_u: the plan's u(ρw), else nullopt and the settings'; averages: the plan's.
  ReadingBudgeter(ReadingBudgetSettings settings, std::int64_t session, double white_reflectance,
                  std::optional<Spectrum> white_spectrum, std::optional<double> white_u,
                  int averages);

  // Keeps a reference or dark reading (with its id) taken at `time_s` (Unix seconds). A dark is
  // also the net of the latest reference that has none yet (darks follow their references).
  void Observe(const storage::ReadingRecord& reading, double time_s);

  // The budget of sample reading `sample` taken at `time_s`, or why it cannot be estimated (it
  // names no reference or an unknown one, a band of the reference is dark, …). pose_gradient:
  // the reading's (pose_gradient.h); nullopt: the pose is not estimated.
  Result<uncertainty::ReadingBudget> Estimate(
      const storage::ReadingRecord& sample, double time_s,
      std::optional<uncertainty::PoseGradient> pose_gradient = std::nullopt) const;

  // The budgets of a finished session's sample readings (`samples`, each at its recorded_at),
  // once every reference has been observed: each with its pose gradient from the others and
  // the lamp drift between its reference and the next. (id, budget) for each sample whose budget
  // can be estimated; one that cannot (see Estimate) is left out, its stored budget kept.
  std::vector<std::pair<std::int64_t, uncertainty::ReadingBudget>> EstimateSession(
      const std::vector<storage::ReadingRecord>& samples) const;

 private:
  struct Kept {
    std::vector<double> radiance;
    int integration_ms = 0;
    double theta_i = 0;
    double time_s = 0;
    std::optional<std::int64_t> dark;  // references: the dark taken after it
  };
  Result<std::optional<uncertainty::LampDrift>> DriftOf(std::int64_t reference,
                                                        double time_s) const;
  Result<std::vector<double>> WhiteOn(const WavelengthGrid& grid) const;

  ReadingBudgetSettings settings_;
  std::int64_t session_;
  double white_reflectance_;
  std::optional<Spectrum> white_spectrum_;
  double white_u_;
  int averages_;
  std::map<std::int64_t, Kept> references_;  // by id: ids increase with time
  std::map<std::int64_t, Kept> darks_;
};

}  // namespace brdf::daemon
