// The lamp's drift between a session's white references (docs/uncertainty.md, "Lamp drift"): the
// relative change δ of the white's net signal from one reference to another, cosine-corrected
// and taken as the median over bands, and the share w of it that falls on a sample reading.
// The budget takes the pair as its lamp_drift input (budget.h's LampDrift). Pure: no I/O.
#pragma once

#include <optional>
#include <vector>

#include "core/status.h"
#include "core/uncertainty/budget.h"

namespace brdf::uncertainty {

// One white reference as the drift needs it.
struct ReferenceObservation {
  std::vector<double> net;  // I0 − D per band (I0 alone when no dark was taken)
  double theta_r_deg = 0;   // the white's incidence
  double time_s = 0;        // when it was taken (any clock, the same for all)
};

// δ from reference `from` to reference `to`: median over bands of
// (to.net / cos θr,to) / (from.net / cos θr,from) − 1, over the bands where both are > 0.
// Errors: sizes differ, no band where both are > 0, θr outside [0°, 90°).
Result<double> RelativeChange(const ReferenceObservation& from, const ReferenceObservation& to);

// The drift a sample reading taken at `time_s` carries, its reference being `own`:
// - with the session's next reference `next`: δ(own → next), w = (t − t_own) / (t_next − t_own);
// - else with the one before, `previous`: δ(previous → own), w = (t − t_own) / (t_own − t_prev);
// - else with a configured rate per hour: δ = rate, w = (t − t_own) / 3600 s;
// - else nullopt (not estimated).
// w is never negative (a reading taken before its reference's clock counts as at it). Errors from
// RelativeChange, and references whose times do not increase.
Result<std::optional<LampDrift>> DriftOfReading(double time_s, const ReferenceObservation& own,
                                                const std::optional<ReferenceObservation>& previous,
                                                const std::optional<ReferenceObservation>& next,
                                                std::optional<double> rate_per_hour);

}  // namespace brdf::uncertainty
