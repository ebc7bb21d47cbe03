// The engine's loop for adaptive sessions (docs/adaptive.md, "Rounds as steps"): when every
// stored step of an adaptive session is done, either the next round is chosen from the committed
// sample readings and stored with its steps in one transaction (then the executor runs them like
// any steps), or the session stops (target reached, a budget spent, nothing to gain).
//
// Deterministic: the same committed readings and steps give the same round, so a crash after a
// round's readings and before the next round is stored makes the engine choose that same round
// again on restart. The uncertainty model is injected (UncertaintyModelFactory); core/adaptive
// stays pure.
//
// What the chooser is given:
//   - readings: every sample reading committed, in id order: its pose (model angles), directions,
//     a scalar BRDF (the mean of its BRDF over the bands within 400–700 nm, kSummaryBands) and a
//     relative standard uncertainty (the mean of its stored budget's combined u over the same
//     bands over the mean of the budget's quantity there). A reading without a budget (not
//     estimated), or whose BRDF cannot be derived (no reference), gets
//     kFallbackRelativeUncertainty; one whose BRDF cannot be derived gets brdf 0.
//   - the rig's state: where the last stored step left it, and the spend so far by the plan's
//     timing model for real devices (time scale 1): sample readings, rig seconds (prompts at the
//     operator's time), prompts.
//   - the candidates: adaptive::CandidatePoses, or in the sample-fixed form FixedCandidates
//     (core/adaptive/sample_fixed_design.h).
//   - the unreadable poses: those of the sample steps the executor skipped because the meter
//     overloaded there (executor.h); they are never chosen again. The skipped marks are stored,
//     so a restarted daemon gives the chooser the same set.
// The chosen round becomes steps by adaptive::RoundSteps (core/adaptive/round_steps.h): a
// sample-fixed round in prompt order, and poses cut from the end while the steps would pass the
// budget.
#pragma once

#include <cstdint>
#include <functional>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "brdf/v1/brdf.pb.h"
#include "brdf/v1/plan.pb.h"
#include "core/adaptive/adaptive_spec.h"
#include "core/adaptive/round_chooser.h"
#include "core/adaptive/stop_rule.h"
#include "core/adaptive/uncertainty_model.h"
#include "core/plan/rig_description.h"
#include "core/status.h"
#include "storage/records.h"
#include "storage/session_store.h"

namespace brdf::daemon {

// Makes the uncertainty model of an adaptive plan (the daemon's: adaptive::MakeInterpolatedModel).
using UncertaintyModelFactory =
    std::function<std::unique_ptr<adaptive::UncertaintyModel>(const adaptive::AdaptiveSpec&)>;

// The bands a reading's scalar summary is taken over, nm (inclusive).
inline constexpr double kSummaryBandsMinNm = 400;
inline constexpr double kSummaryBandsMaxNm = 700;
// The relative standard uncertainty given to a reading that has no stored budget.
inline constexpr double kFallbackRelativeUncertainty = 0.05;

// What the engine decided after the last stored step.
struct RoundDecision {
  std::optional<storage::RoundRecord> round;                    // stored with its steps: run them
  adaptive::StopReason stop = adaptive::StopReason::kContinue;  // no round: why it stops
  double uncertainty_left = 0;
  adaptive::Spend spent;       // before the round (the seed included)
  adaptive::Spend round_cost;  // the stored round's own steps (zero when none is stored)
  int rounds = 0;              // rounds stored, this one included
};

// What a round meant for the budget: the session's spend when it was chosen and its own steps'
// cost, both by the timing model for real devices.
struct RoundSpend {
  adaptive::Spend before;
  adaptive::Spend cost;
};

// Chooses the next round of adaptive session `session` (every stored step done) and stores it
// with its steps (SessionStore::AppendRound), or says why the session stops. `plan` is the
// session's (an adaptive plan), `rig` the rig plans are expanded for.
Result<RoundDecision> NextRound(storage::SessionStore& store, std::int64_t session,
                                const v1::Plan& plan, const plan::RigDescription& rig,
                                const adaptive::UncertaintyModel& model);

// The session's sample readings as the chooser sees them (see above), in id order.
Result<std::vector<adaptive::ReadingSoFar>> ReadingsSoFar(storage::SessionStore& store,
                                                          std::int64_t session,
                                                          const v1::Plan& plan,
                                                          const plan::RigDescription& rig);

// The session's stored rounds as ListAdaptiveRounds gives them, oldest first, each with its
// RoundSpend from the stored steps (empty for a session without rounds).
Result<std::vector<v1::AdaptiveRound>> StoredRounds(storage::SessionStore& store,
                                                    std::int64_t session, const v1::Plan& plan,
                                                    const plan::RigDescription& rig);

// The events WatchSession carries (brdf.v1.AdaptiveRound, AdaptiveStop).
v1::AdaptiveRound ToProtoRound(const storage::RoundRecord& round, const RoundSpend& spend);
v1::AdaptiveStop ToProtoStop(const RoundDecision& decision);
// The reason a stopped session completes with: "adaptive: target reached; uncertainty left
// 0.0412 (target 0.05); 3 rounds, 212 readings, 31.5 min of rig time, 40 prompts".
std::string StopText(const RoundDecision& decision, const adaptive::AdaptiveSpec& spec);

}  // namespace brdf::daemon
