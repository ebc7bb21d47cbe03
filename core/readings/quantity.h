// The three quantities a session's sample readings give (docs: README "Geometry and units"):
//   radiance     I − D                                (D: the dark the reading names, if any)
//   reflectance  R = (I − D) / (I0 − D)               (I0: the reference the reading names)
//   BRDF         f = R · ρw / π · cos θi,ref / cos θi (θi,ref: the reference reading's θi;
//                                                      ρw: the session's white reflectance)
// The one Quantity of brdfd: the daemon's index, the exports and the tools name it so. Pure.
#pragma once

#include <string>
#include <string_view>

#include "core/status.h"

namespace brdf {

enum class Quantity { kRadiance = 0, kReflectance = 1, kBrdf = 2 };
inline constexpr int kQuantityCount = 3;

const char* QuantityName(Quantity q);  // "radiance", "reflectance", "brdf"
// The unit of the quantity's values: "W·m⁻²·sr⁻¹·nm⁻¹", "1 (unitless)", "sr⁻¹".
const char* QuantityUnit(Quantity q);
// One sentence defining the quantity, for file headers.
std::string QuantityDefinition(Quantity q);
// kInvalidArgument naming the accepted words.
Result<Quantity> ParseQuantity(std::string_view name);

}  // namespace brdf
