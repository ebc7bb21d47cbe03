// Plan files: the JSON form of brdf.v1.Plan (examples/plans/*.json), parsed with protobuf's JSON
// utilities through core/plan/plan_json.h, the same parser the daemon's tests use. Errors name the
// file, the line and column, and the field: "plan.json: plan JSON, line 4, column 5
// (sampleRotation.alpa): unknown field \"alpa\" …".
#pragma once

#include <string>

#include "brdf/v1/plan.pb.h"
#include "core/status.h"

namespace brdf::ctl {

// Reads and parses `path` ("-" reads standard input). kNotFound when the file cannot be opened,
// kInvalidArgument when it does not parse.
Result<v1::Plan> ReadPlanFile(const std::string& path);

}  // namespace brdf::ctl
