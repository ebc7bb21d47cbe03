// Each sample reading's uncertainty budget, estimated as the executor commits it
// (docs/uncertainty.md): the session's references and darks so far, the plan's averages and
// white standard, and the configured terms go into core/uncertainty's EstimateReadingBudget. The
// budget is of the BRDF. What a reading's commit cannot know yet stays "not estimated" in the
// budget: the pose (no neighbouring readings yet) and, until the session has two references and
// no rate is configured, the lamp drift.
#pragma once

#include <cstdint>
#include <map>
#include <optional>
#include <vector>

#include "core/spectrum.h"
#include "core/status.h"
#include "core/uncertainty/budget.h"
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
  // names no reference or an unknown one, a band of the reference is dark, …).
  Result<uncertainty::ReadingBudget> Estimate(const storage::ReadingRecord& sample,
                                              double time_s) const;

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
