// The picks of an adaptive round as adaptive_rounds.picks holds them (schema.md, v6): one line
// per pose, "alpha beta gamma delta gain", model angles in degrees, numbers written so that they
// read back exactly (17 significant digits).
#pragma once

#include <string>
#include <string_view>
#include <vector>

#include "core/status.h"
#include "storage/records.h"

namespace brdf::storage {

std::string EncodePicks(const std::vector<RoundPick>& picks);
// kInvalidArgument naming the line when a line is not five numbers.
Result<std::vector<RoundPick>> DecodePicks(std::string_view text);

}  // namespace brdf::storage
