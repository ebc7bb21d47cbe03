// The uncertainty of a MERL or RGL export, which their formats cannot hold, as a JSON sidecar
// (Data.Export's part "uncertainty" with include_uncertainty; docs/uncertainty.md, "Exports"):
// per band, the median and 95th percentile of the relative combined u (u / f) and of its parts
// over the cells of a 5° (θi, θo, φ) grid of the hemisphere — the directions MERL's and RGL's
// cells sample, answered by the same uncertain fill chain (uncertain_chain.h) — and the white
// standard's relative part, the term shared by every cell. Pure: no I/O.
#pragma once

#include <string>

#include "core/call_context.h"
#include "core/export/fill/session_interpolant.h"
#include "core/export/run_control.h"
#include "core/status.h"

namespace brdf::exports {

// The sidecar's JSON text for `in` (the BRDF) exported as `format` ("merl" or "rgl"). Errors:
// kCancelled / kTimeout from `ctx`.
Result<std::string> UncertaintySummaryJson(const SessionInterpolant& in, const std::string& format,
                                           const RunControl& control, const CallContext& ctx);

}  // namespace brdf::exports
