// What brdf-interp's commands share: exit codes, option parsing helpers, method names.
#pragma once

#include <memory>
#include <string>
#include <vector>

#include "core/interp/interpolator.h"
#include "core/status.h"

namespace brdf::interp_tool {

inline constexpr int kExitOk = 0;
inline constexpr int kExitFailure = 1;  // the system failed (cannot write the output, a bug)
inline constexpr int kExitUsage = 2;    // the input is wrong (arguments, a CSV file, options)

// The exit code for an error status: kExitUsage for kInvalidArgument, else kExitFailure.
int ExitCodeFor(const Status& status);

// "octant", "octant-reference", "delaunay", "nearest".
const std::vector<std::string>& MethodChoices();

// The interpolator for a --method value ("octant-reference": the O(N) scan of the octant method).
Result<std::unique_ptr<interp::Interpolator>> MakeNamedInterpolator(
    const std::string& method, std::shared_ptr<const interp::SampleSet> samples,
    const interp::Options& options);

// "1,2.5,3" → {1, 2.5, 3}; errors name `option` and the bad item.
Result<std::vector<double>> ParseNumberList(const std::string& text, const std::string& option);

}  // namespace brdf::interp_tool
