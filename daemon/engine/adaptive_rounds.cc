#include "daemon/engine/adaptive_rounds.h"

#include <algorithm>
#include <cstdio>
#include <span>
#include <string>
#include <utility>

#include "core/adaptive/candidates.h"
#include "core/adaptive/round_cost.h"
#include "core/adaptive/round_steps.h"
#include "core/adaptive/sample_fixed_design.h"
#include "core/geometry.h"
#include "core/plan/expand_steps.h"
#include "core/plan/plan_settings.h"
#include "core/plan/sample.h"
#include "core/readings/derive.h"
#include "daemon/wire/plan.h"
#include "daemon/wire/round.h"
#include "daemon/wire/values.h"
#include "storage/session_readings.h"

namespace brdf::daemon {
namespace {

// Mean of `values` over the bands of `grid` within the summary range; nullopt when none is.
std::optional<double> SummaryMean(const std::vector<double>& values, const WavelengthGrid& grid) {
  double sum = 0;
  int n = 0;
  for (std::size_t i = 0; i < values.size() && i < grid.count; ++i) {
    const double nm = grid.at(i);
    if (nm < kSummaryBandsMinNm - 1e-9 || nm > kSummaryBandsMaxNm + 1e-9) continue;
    sum += values[i];
    ++n;
  }
  if (n == 0) return std::nullopt;
  return sum / n;
}

// The relative standard uncertainty of a sample from its stored budget (combined u over the
// budget's quantity, both averaged over the summary bands), or the fallback.
double RelativeUncertainty(const storage::ReadingRecord& r, const SampleQuantities& q) {
  if (!r.uncertainty.has_value() || !q.has(r.uncertainty->quantity)) {
    return kFallbackRelativeUncertainty;
  }
  const std::optional<double> u = SummaryMean(r.uncertainty->combined, r.grid);
  const std::optional<double> v = SummaryMean(q.of(r.uncertainty->quantity), r.grid);
  if (!u.has_value() || !v.has_value() || *v <= 0 || !(*u >= 0)) {
    return kFallbackRelativeUncertainty;
  }
  return *u / *v;
}

// What `after` spent beyond `before`.
adaptive::Spend Difference(const adaptive::Spend& after, const adaptive::Spend& before) {
  return {after.readings - before.readings, after.seconds - before.seconds,
          after.prompts - before.prompts};
}

storage::RoundRecord MakeRecord(std::int64_t session, int number, int first_step,
                                const adaptive::Round& round, double left, int readings) {
  storage::RoundRecord r;
  r.session_id = session;
  r.round = number;
  r.first_step = first_step;
  for (const adaptive::ChosenPose& c : round.poses) r.picks.push_back({c.pose, c.predicted_gain});
  r.predicted_gain = round.predicted_gain;
  r.uncertainty_left = left;
  r.readings_used = readings;
  return r;
}

// The poses (model angles) of the sample steps the executor skipped: the meter could not read
// them (executor.h), so the chooser never picks them again.
std::vector<Pose> SkippedPoses(const std::vector<storage::StepRecord>& steps,
                               const plan::RigDescription& rig) {
  std::vector<Pose> out;
  for (const storage::StepRecord& s : steps) {
    if (s.kind == storage::StepKind::kSample && s.state == storage::StepState::kSkipped) {
      out.push_back(ToModelAngles(s.pose, rig.convention));
    }
  }
  return out;
}

}  // namespace

Result<std::vector<adaptive::ReadingSoFar>> ReadingsSoFar(storage::SessionStore& store,
                                                          std::int64_t session,
                                                          const v1::Plan& plan,
                                                          const plan::RigDescription& rig) {
  BRDF_ASSIGN_OR_RETURN(storage::SessionRecord record, store.GetSession(session));
  BRDF_ASSIGN_OR_RETURN(std::vector<storage::StepRecord> steps, store.GetSteps(session));
  ReadingDeriver deriver(record.white_reflectance.value_or(kWhiteStandardReflectance),
                         plan::WhiteReflectanceSpectrumOf(plan));
  std::vector<adaptive::ReadingSoFar> out;
  BRDF_RETURN_IF_ERROR(store.ForEachReading(session, [&](const storage::ReadingRecord& r) {
    const std::optional<SampleQuantities> q = deriver.Fold(storage::ToReading(r));
    if (!q.has_value() || r.kind != ReadingKind::kSample) return Status::Ok();
    adaptive::ReadingSoFar so_far;
    // The pose the step asked for (the one the chooser compares candidates with).
    const std::size_t step = static_cast<std::size_t>(r.step_index);
    so_far.pose = ToModelAngles(step < steps.size() ? steps[step].pose : r.pose, rig.convention);
    so_far.directions = r.directions;
    const bool has_brdf = q->has(Quantity::kBrdf);
    so_far.brdf = has_brdf ? SummaryMean(q->of(Quantity::kBrdf), r.grid).value_or(0) : 0;
    so_far.relative_uncertainty =
        has_brdf ? RelativeUncertainty(r, *q) : kFallbackRelativeUncertainty;
    out.push_back(so_far);
    return Status::Ok();
  }));
  return out;
}

Result<RoundDecision> NextRound(storage::SessionStore& store, std::int64_t session,
                                const v1::Plan& plan, const plan::RigDescription& rig,
                                const adaptive::UncertaintyModel& model) {
  const adaptive::AdaptiveSpec spec = adaptive::ResolveAdaptive(plan.adaptive());
  BRDF_ASSIGN_OR_RETURN(std::vector<adaptive::ReadingSoFar> readings,
                        ReadingsSoFar(store, session, plan, rig));
  BRDF_ASSIGN_OR_RETURN(std::vector<storage::StepRecord> stored, store.GetSteps(session));
  BRDF_ASSIGN_OR_RETURN(std::vector<storage::RoundRecord> rounds, store.GetRounds(session));
  const std::vector<plan::Step> steps = ToPlanSteps(stored);

  RoundDecision decision;
  decision.rounds = static_cast<int>(rounds.size());
  decision.spent = adaptive::SpendOfSteps(steps, plan, rig);
  // One map for the stop rule and the chooser: building it is the round's main cost.
  const std::unique_ptr<adaptive::UncertaintyMap> map = model.Map(readings);
  decision.uncertainty_left = map->Remaining();
  decision.stop =
      adaptive::ShouldStop(decision.uncertainty_left, spec.target, spec.budget, decision.spent);
  if (decision.stop != adaptive::StopReason::kContinue) return decision;

  const plan::ExpansionStart start = plan::StartAfter(steps, plan, rig);
  const std::vector<Pose> candidates =
      spec.sample_fixed ? adaptive::FixedCandidates(spec) : adaptive::CandidatePoses(spec, rig);
  const std::vector<Pose> unreadable = SkippedPoses(stored, rig);
  const adaptive::RoundInput input{readings,       candidates,  start.model,
                                   decision.spent, spec.budget, unreadable};
  const adaptive::RoundCost cost(plan, rig);
  // (A sample-fixed plan gets no finer candidates: refine_candidates.h.)
  adaptive::Round round =
      adaptive::ChooseRound(input, *map, cost, {.max_readings = spec.round_readings});
  // In measurement order (a sample-fixed round in prompt order), within the budget step by step.
  const std::vector<plan::Step> round_steps =
      adaptive::RoundSteps(plan, rig, steps, decision.spent, start, spec.budget, round);
  decision.stop = adaptive::AfterChoosing(round);
  if (decision.stop != adaptive::StopReason::kContinue) return decision;

  const int first = static_cast<int>(stored.size());
  std::vector<storage::StepRecord> added;
  for (const plan::Step& s : round_steps) added.push_back(ToStepRecord(s));
  storage::RoundRecord record =
      MakeRecord(session, decision.rounds + 1, first, round, decision.uncertainty_left,
                 static_cast<int>(readings.size()));
  record.step_count = static_cast<int>(added.size());
  BRDF_RETURN_IF_ERROR(store.AppendRound(record, added));
  // RoundSteps costed the stored steps with the round's (round.cost): one sample reading a pose.
  decision.round_cost = {static_cast<int>(round.poses.size()), round.cost.seconds,
                         round.cost.prompts};
  decision.round = std::move(record);
  decision.rounds += 1;
  return decision;
}

Result<std::vector<v1::AdaptiveRound>> StoredRounds(storage::SessionStore& store,
                                                    std::int64_t session, const v1::Plan& plan,
                                                    const plan::RigDescription& rig) {
  BRDF_ASSIGN_OR_RETURN(std::vector<storage::RoundRecord> rounds, store.GetRounds(session));
  std::vector<v1::AdaptiveRound> out;
  if (rounds.empty()) return out;
  BRDF_ASSIGN_OR_RETURN(std::vector<storage::StepRecord> stored, store.GetSteps(session));
  const std::vector<plan::Step> steps = ToPlanSteps(stored);
  const std::span<const plan::Step> all(steps);
  for (const storage::RoundRecord& r : rounds) {
    const std::size_t first = std::min(static_cast<std::size_t>(r.first_step), all.size());
    const std::size_t end = std::min(first + static_cast<std::size_t>(r.step_count), all.size());
    RoundSpend spend;
    spend.before = adaptive::SpendOfSteps(all.first(first), plan, rig);
    spend.cost = Difference(adaptive::SpendOfSteps(all.first(end), plan, rig), spend.before);
    out.push_back(ToProtoRound(r, spend));
  }
  return out;
}

v1::AdaptiveRound ToProtoRound(const storage::RoundRecord& round, const RoundSpend& spend) {
  return ToProtoRound(storage::ArchivedRound{round, spend.before.seconds, spend.before.prompts,
                                             spend.cost.seconds, spend.cost.prompts});
}

v1::AdaptiveStop ToProtoStop(const RoundDecision& decision) {
  v1::AdaptiveStop out;
  out.set_reason(adaptive::StopReasonText(decision.stop));
  out.set_uncertainty_left(decision.uncertainty_left);
  out.set_readings(static_cast<std::uint32_t>(decision.spent.readings));
  out.set_rig_s(decision.spent.seconds);
  out.set_prompts(static_cast<std::uint32_t>(decision.spent.prompts));
  out.set_rounds(static_cast<std::uint32_t>(decision.rounds));
  return out;
}

std::string StopText(const RoundDecision& decision, const adaptive::AdaptiveSpec& spec) {
  char text[320];
  std::snprintf(text, sizeof text,
                "adaptive: %s; uncertainty left %.4g (target %.4g); %d round(s), %d readings, "
                "%.1f min of rig time, %d prompts",
                adaptive::StopReasonText(decision.stop), decision.uncertainty_left,
                spec.target.level, decision.rounds, decision.spent.readings,
                decision.spent.seconds / 60, decision.spent.prompts);
  return text;
}

}  // namespace brdf::daemon
