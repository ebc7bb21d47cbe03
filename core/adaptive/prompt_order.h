// The order in which a sample-fixed round's poses are prompted (sample_fixed_design.h): each pose
// is the operator carrying lamp and detector by hand to new directions, so the poses are put in
// an order that keeps those carries short. A pose's setting is its direction pair placed as the
// expander places it (the lamp at (θi, φi = 0), the detector at (θo, φo = φ)); the travel from
// one setting to the next is the angle the lamp turns plus the angle the detector turns, degrees
// (great-circle angles between the directions).
//
// The order: nearest neighbour from where lamp and detector stand (ties: the smaller (θi, θo,
// φ)), then 2-opt (a stretch of the order reversed while that shortens the travel, at most
// kMaxOrderPasses passes over the pairs). The result is kept only when its travel is shorter than
// the given order's; else the given order stands. So the travel never grows, and the same poses
// in the same order from the same setting give the same order. Pure.
#pragma once

#include <span>
#include <vector>

#include "core/adaptive/round_chooser.h"
#include "core/pose.h"

namespace brdf::adaptive {

inline constexpr int kMaxOrderPasses = 50;

// The travel (degrees) from setting `a` to setting `b` (model angles of sample-fixed poses).
double SettingTravel(const Pose& a, const Pose& b);

// The travel of `poses` in order, starting from `from`.
double PromptTravel(const Pose& from, std::span<const Pose> poses);

// `poses` in prompt order (see above), starting from `from`.
std::vector<Pose> OrderForPrompts(const Pose& from, std::span<const Pose> poses);

// The round's poses put in prompt order from `from`; its gains go with their poses. The round's
// cost does not change (every sample-fixed pose costs the same, FixedPoseCost).
void OrderRoundForPrompts(Round& round, const Pose& from);

}  // namespace brdf::adaptive
