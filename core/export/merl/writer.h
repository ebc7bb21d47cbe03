// A session exported as a MERL ".binary" (merl/layout.h): every cell of the 90 × 90 × 180
// half/difference table asks a SpectrumSource (the session's interpolator of the BRDF, sr⁻¹) for
// the spectrum at the cell's directions, turns it into linear sRGB under D65 (spectral_rgb.h) and
// stores it divided by MERL's channel scales. Parallel, with progress and cancellation
// (run_control.h); the result does not depend on the thread count.
//
// Cells that hold no BRDF keep MERL's missing value, −1: cells whose directions are below the
// surface (θh + θd beyond the horizon), and cells the source cannot fill (an empty octant, outside
// the hull), each counted. A linear sRGB component below 0 (a colour outside the sRGB gamut, or
// noise) is clamped to 0, since readers take negative values for missing data; those are counted
// too.
#pragma once

#include <cstddef>
#include <map>
#include <ostream>
#include <string>

#include "core/call_context.h"
#include "core/export/fill/spectrum_source.h"
#include "core/export/merl/layout.h"
#include "core/export/run_control.h"
#include "core/export/spectral_rgb.h"
#include "core/status.h"

namespace brdf::exports {

struct MerlReport {
  std::size_t cells = kMerlCells;
  std::size_t filled = 0;                                // cells with an RGB value
  std::size_t below_horizon = 0;                         // −1: ωi or ωo below the surface
  std::map<interp::InterpStatus, std::size_t> unfilled;  // −1: the source had no value (by why)
  std::size_t clamped = 0;  // filled cells with a negative component set to 0
  std::size_t unfilled_total() const;
  // "1458000 cells: 512345 filled, 700000 below the horizon, 245655 unfilled (… empty_octant),
  //  12 clamped to the sRGB gamut"
  std::string Summary() const;
};

struct MerlExport {
  MerlTable table;
  MerlReport report;
};

// Errors: weights on another wavelength grid than `bands` (kInvalidArgument), kCancelled /
// kTimeout from `ctx`.
Result<MerlExport> BuildMerlTable(const SpectrumSource& source, const WavelengthGrid& bands,
                                  const SpectralRgbWeights& rgb, const RunControl& control,
                                  const CallContext& ctx);

// Writes the file: dims (90, 90, 180) as little-endian int32, then the doubles. kIoError when the
// stream fails.
Status WriteMerl(const MerlTable& table, std::ostream& out);

}  // namespace brdf::exports
