// A session's interpolant as every export that fills a table builds it (brdf-export and the
// daemon's Data.Export alike, so that the same session and options give the same bytes): the
// chosen interpolation method on the derived samples, behind the fill chain (fill/chain.h) —
// alone with FillPolicy kNone; with kChain followed by Delaunay on the same samples and options
// (unless the method is Delaunay) and by the Cook-Torrance (GGX) model fitted to the samples.
// Also the RGL export of such an interpolant (rgl/writer.h), with its microfacet distribution
// from the session's retro-reflection readings or, without them, from the fitted model. Pure:
// no I/O.
#pragma once

#include <cstddef>
#include <cstdint>
#include <memory>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "core/call_context.h"
#include "core/export/fill/chain.h"
#include "core/export/grid/text.h"
#include "core/export/rgl/writer.h"
#include "core/export/run_control.h"
#include "core/export/session_data.h"
#include "core/export/spectral_rgb.h"
#include "core/fit/fit.h"
#include "core/interp/interpolator.h"
#include "core/status.h"
#include "core/uncertainty/held_out.h"

namespace brdf::exports {

// The parts are shared: ShareSessionInterpolant hands another export the same derived samples,
// indexes and model (the daemon keeps them per session snapshot, daemon/api/export_cache.h), each
// with a chain of its own, so that each export counts its own cells. The parts are immutable and
// their queries thread-safe.
struct SessionInterpolant {
  std::shared_ptr<const DerivedSamples> derived;
  std::shared_ptr<const interp::SampleSet> samples;
  interp::Method method = interp::Method::kOctant;
  interp::Options options;
  FillPolicy policy = FillPolicy::kNone;
  std::shared_ptr<const interp::Interpolator> interpolator;  // the chosen method
  std::shared_ptr<const interp::Interpolator> fallback;  // kChain: Delaunay, unless the method is
  std::shared_ptr<const fit::CookTorranceFit> model;     // kChain: the fitted model
  std::unique_ptr<FillChain> chain;                      // ask chain->Source(), read its Tally()
  // The interpolation term's calibration of the chosen method and of the fallback, and the model
  // cells' (fill/model_uncertainty.h), over these samples (uncertainty/held_out.h): computed by the
  // first export with uncertainty (uncertain_chain.h, InterpolantCalibrations) and shared with the
  // other parts, so that a kept interpolant is calibrated once however many exports ask it.
  struct Calibrations {
    uncertainty::CalibrationOnce chosen;
    uncertainty::CalibrationOnce fallback;
    uncertainty::CalibrationOnce model;  // the model cells' (model_uncertainty.h)
  };
  std::shared_ptr<const Calibrations> calibrations = std::make_shared<const Calibrations>();

  // The symmetry options, axis scales and fill counts so far, for a grid's sidecar.
  InterpolantInfo Info() const;
};

// Errors: no usable sample (from the interpolator), a sample the fit refuses or a failed fit
// (with context naming the fill chain's stage), kCancelled / kTimeout from `ctx` (the fit).
Result<SessionInterpolant> BuildSessionInterpolant(std::shared_ptr<const DerivedSamples> derived,
                                                   interp::Method method,
                                                   const interp::Options& options,
                                                   FillPolicy policy, const CallContext& ctx);
inline Result<SessionInterpolant> BuildSessionInterpolant(DerivedSamples derived,
                                                          interp::Method method,
                                                          const interp::Options& options,
                                                          FillPolicy policy,
                                                          const CallContext& ctx) {
  return BuildSessionInterpolant(std::make_shared<const DerivedSamples>(std::move(derived)), method,
                                 options, policy, ctx);
}

// The same parts as `built` (shared, not copied) behind a chain of its own, whose tally starts at
// zero: what another export of the same samples and settings asks.
SessionInterpolant ShareSessionInterpolant(const SessionInterpolant& built);

// The most samples the fill chain's model is fitted to. A model of four parameters per band is
// determined long before this many; a 50,000-reading session took 7 s to fit in full against
// about 1 s for this subset (tools/brdf-export/README.md, "Fill policy").
inline constexpr std::size_t kModelFitSamples = 8192;

// Which samples of a set of `count` the model is fitted to: all of them up to kModelFitSamples,
// else kModelFitSamples chosen by a fixed hash of their index (the same for the same count, in
// no pattern a rig's regular grid of poses could alias with), in ascending order.
std::vector<std::size_t> ModelFitSamples(std::size_t count);

// The fill chain's model: the Cook-Torrance (GGX) model fitted to the samples of `samples`
// that ModelFitSamples chooses (coordinates θi, θo, φ; spectra on `grid`), in the set's order.
// Errors: a sample the fit refuses (naming its reading), a failed fit, kCancelled / kTimeout
// from `ctx`.
Result<fit::CookTorranceFit> FitSampleModel(const interp::SampleSet& samples,
                                            const WavelengthGrid& grid, const CallContext& ctx);

struct SessionRglOptions {
  std::size_t theta_i_count = 24;  // θi slices
  std::size_t sample_res = 48;     // nodes per side of the warped square
  // When set: an RGB file (linear sRGB under D65) instead of the spectral one.
  std::optional<SpectralRgbWeights> rgb;
};

// The RGL material of `session` (its id and name go in the file's description) from `in` (the
// BRDF): the fill chain's source answers every node above the surface; where it has none (fill
// policy none) the nearest reading's value is taken (counted as fallback). θi slices run up to
// the largest θi or θo measured (at most 89°). Errors: as BuildRgl, and the fit when the session
// has no retro-reflection readings.
Result<RglExport> BuildSessionRgl(const Session& session, const SessionInterpolant& in,
                                  const SessionRglOptions& options, const RunControl& control,
                                  const CallContext& ctx);

}  // namespace brdf::exports
