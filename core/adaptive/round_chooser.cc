#include "core/adaptive/round_chooser.h"

#include <algorithm>
#include <cstddef>
#include <limits>
#include <memory>
#include <optional>
#include <tuple>

#include "core/adaptive/seed_design.h"
#include "core/geometry.h"

namespace brdf::adaptive {
namespace {

auto Key(const Pose& p) {
  return std::tie(p.delta, p.gamma, p.alpha, p.beta);
}

bool SameSetting(const Pose& a, const Pose& b) {
  return a.delta == b.delta && a.gamma == b.gamma;
}

// Candidates already measured (a reading's pose) or unreadable start out taken.
std::vector<bool> MeasuredAlready(const RoundInput& input) {
  std::vector<Pose> measured(input.unreadable.begin(), input.unreadable.end());
  for (const ReadingSoFar& r : input.readings) measured.push_back(r.pose);
  std::sort(measured.begin(), measured.end(),
            [](const Pose& a, const Pose& b) { return Key(a) < Key(b); });
  std::vector<bool> taken(input.candidates.size());
  for (std::size_t i = 0; i < taken.size(); ++i) {
    taken[i] = std::binary_search(measured.begin(), measured.end(), input.candidates[i],
                                  [](const Pose& a, const Pose& b) { return Key(a) < Key(b); });
  }
  return taken;
}

// The detector positions (δ, γ) a round has reached so far, the rig's present one first, and how
// many of them cost the operator a relocation (a prompt) to reach. Grouping measures each setting
// once (GroupBySetting), so a pick at a setting reached already costs its move and reading alone.
class Settings {
 public:
  // Inactive (every pick costed by RoundCost::Step alone) in the sample-fixed form, where every
  // pose is its own prompt, and for ungrouped rounds.
  Settings(const Pose& rig_at, const RoundCost& cost, const RoundOptions& options)
      : reached_{rig_at},
        cost_(cost),
        active_(options.group_by_delta && !cost.sample_fixed()),
        limit_(options.max_relocations) {}

  bool Reached(const Pose& p) const {
    return std::any_of(reached_.begin(), reached_.end(),
                       [&](const Pose& s) { return SameSetting(s, p); });
  }
  // What a pick at `to` costs after one at `from` (nullopt: its relocation is one too many).
  std::optional<PoseCost> Cost(const Pose& from, const Pose& to) const {
    if (!active_) return cost_.Step(from, to);
    if (Reached(to)) return PoseCost{cost_.MoveAndReadSeconds(from, to), 0};
    const PoseCost step = cost_.Step(from, to);
    if (step.prompts > 0 && limit_ >= 0 && relocations_ >= limit_) return std::nullopt;
    return step;
  }
  void Add(const Pose& p, const PoseCost& paid) {
    if (!active_ || Reached(p)) return;
    reached_.push_back(p);
    if (paid.prompts > 0) ++relocations_;
  }

 private:
  std::vector<Pose> reached_;
  const RoundCost& cost_;
  bool active_;
  int limit_;
  int relocations_ = 0;
};

// The greedy picks, in pick order.
std::vector<ChosenPose> PickGreedy(const RoundInput& input, UncertaintyMap& map,
                                   const RoundCost& cost, const RoundOptions& options,
                                   StopReason* limited_by) {
  std::vector<Directions> directions;
  directions.reserve(input.candidates.size());
  for (const Pose& c : input.candidates) directions.push_back(PoseToDirections(c));
  std::vector<bool> taken = MeasuredAlready(input);
  std::vector<ChosenPose> picks;
  Pose at = input.rig_at;
  Spend spent = input.spent;
  Settings settings(input.rig_at, cost, options);
  while (static_cast<int>(picks.size()) < options.max_readings) {
    std::size_t best = input.candidates.size();
    double best_score = -std::numeric_limits<double>::infinity();
    double best_gain = 0;
    PoseCost best_cost;
    for (std::size_t i = 0; i < input.candidates.size(); ++i) {
      if (taken[i]) continue;
      const Pose& c = input.candidates[i];
      const double gain = map.PredictedGain(directions[i]);
      if (!(gain > 0)) continue;
      const std::optional<PoseCost> priced = settings.Cost(at, c);
      if (!priced.has_value()) continue;
      const PoseCost step = *priced;
      if (const StopReason limit = LimitPassed(input.budget, spent, step, 1);
          limit != StopReason::kContinue) {
        if (*limited_by == StopReason::kContinue) *limited_by = limit;
        continue;
      }
      const double charged = options.group_by_delta ? step.seconds : cost.MoveAndReadSeconds(at, c);
      const double score = gain / std::max(charged, 1e-6);
      if (score > best_score || (score == best_score && Key(c) < Key(input.candidates[best]))) {
        best = i;
        best_score = score;
        best_gain = gain;
        best_cost = step;
      }
    }
    if (best == input.candidates.size()) break;
    taken[best] = true;
    map.Assume(directions[best]);
    at = input.candidates[best];
    settings.Add(at, best_cost);
    spent.readings += 1;
    spent.seconds += best_cost.seconds;
    spent.prompts += best_cost.prompts;
    picks.push_back({at, best_gain});
  }
  return picks;
}

// The picks grouped by (δ, γ): the rig's present setting first, then in order of first pick;
// each group ordered for short moves.
std::vector<ChosenPose> GroupBySetting(const std::vector<ChosenPose>& picks, const Pose& rig_at) {
  std::vector<Pose> settings;
  for (const ChosenPose& p : picks) {
    if (std::none_of(settings.begin(), settings.end(),
                     [&](const Pose& s) { return SameSetting(s, p.pose); })) {
      settings.push_back(p.pose);
    }
  }
  std::stable_partition(settings.begin(), settings.end(),
                        [&](const Pose& s) { return SameSetting(s, rig_at); });
  std::vector<ChosenPose> out;
  for (const Pose& setting : settings) {
    std::vector<Pose> group;
    for (const ChosenPose& p : picks) {
      if (SameSetting(p.pose, setting)) group.push_back(p.pose);
    }
    OrderForTravel(group);
    for (const Pose& pose : group) {
      for (const ChosenPose& p : picks) {
        if (p.pose == pose) out.push_back(p);
      }
    }
  }
  return out;
}

}  // namespace

StopReason LimitPassed(const Budget& budget, const Spend& spent, const PoseCost& more,
                       int readings) {
  if (budget.max_readings > 0 && spent.readings + readings > budget.max_readings) {
    return StopReason::kReadingBudget;
  }
  if (budget.max_rig_s > 0 && spent.seconds + more.seconds > budget.max_rig_s + 1e-9) {
    return StopReason::kTimeBudget;
  }
  if (budget.max_prompts > 0 && spent.prompts + more.prompts > budget.max_prompts) {
    return StopReason::kPromptBudget;
  }
  return StopReason::kContinue;
}

bool WithinBudget(const Budget& budget, const Spend& spent, const PoseCost& more, int readings) {
  return LimitPassed(budget, spent, more, readings) == StopReason::kContinue;
}

Round ChooseRound(const RoundInput& input, const UncertaintyModel& model, const RoundCost& cost,
                  const RoundOptions& options) {
  const std::unique_ptr<UncertaintyMap> map = model.Map(input.readings);
  return ChooseRound(input, *map, cost, options);
}

Round ChooseRound(const RoundInput& input, UncertaintyMap& map, const RoundCost& cost,
                  const RoundOptions& options) {
  Round round;
  // The caller's candidates and the finer ones, refined from the map before any pick.
  std::vector<Pose> candidates(input.candidates.begin(), input.candidates.end());
  const std::vector<Pose> finer =
      RefinedCandidates(input.readings, input.candidates, map, cost, options.refine);
  candidates.insert(candidates.end(), finer.begin(), finer.end());
  RoundInput all = input;
  all.candidates = candidates;
  std::vector<ChosenPose> picks = PickGreedy(all, map, cost, options, &round.limited_by);
  if (options.group_by_delta) picks = GroupBySetting(picks, input.rig_at);
  std::vector<Pose> poses;
  for (const ChosenPose& p : picks) poses.push_back(p.pose);
  // Costed in measurement order; cut from the end until it fits.
  while (!poses.empty()) {
    round.cost = cost.Sequence(input.rig_at, poses);
    const StopReason limit =
        LimitPassed(input.budget, input.spent, round.cost, static_cast<int>(poses.size()));
    if (limit == StopReason::kContinue) break;
    if (round.limited_by == StopReason::kContinue) round.limited_by = limit;
    poses.pop_back();
    picks.pop_back();
    round.cost = {};
  }
  round.poses = std::move(picks);
  for (const ChosenPose& p : round.poses) round.predicted_gain += p.predicted_gain;
  return round;
}

}  // namespace brdf::adaptive
