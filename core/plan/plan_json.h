// Plans as JSON files: the proto JSON mapping of brdf.v1.Plan (lowerCamelCase names; the
// proto's snake_case names are accepted too). Unknown fields are refused, so a misspelt key
// cannot silently fall back to a default. Examples: examples/plans/*.json.
#pragma once

#include <cstddef>
#include <string>
#include <string_view>

#include "brdf/v1/plan.pb.h"
#include "core/status.h"

namespace brdf::plan {

// Larger plan texts are refused before parsing (a pose list at the step cap is ~8 MB).
inline constexpr std::size_t kMaxPlanJsonBytes = 16 * 1024 * 1024;

// Parses a plan. Errors (kInvalidArgument) say where: "plan JSON, line 3, column 7
// (sampleRotation.alpa): unknown field \"alpa\" …", "plan JSON, line 2, column 21: expected ','
// or '}' …". Only the syntax and the types are checked here; ValidatePlan checks the values.
Result<v1::Plan> ParsePlanJson(std::string_view json);

// The plan as indented JSON (fields left at their defaults are omitted).
Result<std::string> PlanToJson(const v1::Plan& plan);

}  // namespace brdf::plan
