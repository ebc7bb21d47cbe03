// A grid with its uncertainty arrays (docs/uncertainty.md, "Exports", Grid (.npy)): a session's
// interpolant resampled on a regular grid through its uncertain fill chain (uncertain_chain.h) in
// one pass, the values to one sink and the u, u_measurement and u_interpolation planes to three
// more, with the sidecar's "uncertainty" object and the report's warnings. The daemon's export
// (each array a part of its stream, daemon/api/export.cc) and brdf-export (each array a file
// beside the .npy) both call it, so the same session and options give the same arrays. Pure: the
// sinks do the I/O.
#pragma once

#include <array>
#include <string>
#include <vector>

#include "core/call_context.h"
#include "core/export/fill/session_interpolant.h"
#include "core/export/fill/uncertain_chain.h"
#include "core/export/grid/regular_grid.h"
#include "core/export/run_control.h"
#include "core/status.h"

namespace brdf::exports {

// The arrays beside the values, in the order they are handed to the sinks and named in the
// sidecar.
inline constexpr std::array<UncertainPlane, 3> kUncertaintyArrays = {
    UncertainPlane::kCombined, UncertainPlane::kMeasurement, UncertainPlane::kInterpolation};

// The name of `file`'s companion `part`: the part before the extension, the extension `extension`
// (empty: `file`'s own). "grid.npy", "u" → "grid.u.npy"; "paint.binary", "uncertainty", ".json"
// → "paint.uncertainty.json".
std::string CompanionFileName(const std::string& file, const std::string& part,
                              const std::string& extension = "");

// The uncertainty arrays of the values' file `file`, named as CompanionFileName names them, in
// kUncertaintyArrays' order.
std::vector<UncertaintyFile> UncertaintyFiles(const std::string& file);

struct UncertainGrid {
  GridReport report;
  FillTally tally;                    // the cells by the chain's stage
  std::string uncertainty_json;       // the sidecar's "uncertainty" object (UncertaintyJson)
  std::vector<std::string> warnings;  // UncertaintyWarnings
};

// Resamples `in` on `grid` (the bands of in.derived) through MakeUncertainChain(in): the values
// to `values`, plane kUncertaintyArrays[i] to arrays[i] (none null); the sidecar names the arrays
// as UncertaintyFiles(file). Errors: ResampleOnGrid's (the sinks' own included).
Result<UncertainGrid> ResampleWithUncertainty(const SessionInterpolant& in, const RegularGrid& grid,
                                              Quantity quantity, const RunControl& control,
                                              const CallContext& ctx, GridSink& values,
                                              const std::array<GridSink*, 3>& arrays,
                                              const std::string& file);

}  // namespace brdf::exports
