// A session exported in the RGL material format of Dupuy & Jakob, "An Adaptive Parameterization
// for Efficient Material Acquisition and Rendering" (2018): a `tensor_file` (.bsdf) that Mitsuba
// 3's `measured` BSDF, pbrt-v4's `measured` material and the authors' brdf-loader read. The
// format, field by field, is in docs/rgl-format.md.
//
// How the tables are made (isotropic: one φi slice):
//  - the microfacet distribution D(θm) comes from retro-reflection (ωi = ωo) values f(θ) by the
//    power iteration of Dupuy et al. 2015, D ← f(θ) · cos θ · σ[D](θ), normalised so that
//    ∫ D cos θm dω = 1. The caller gives f(θ): from the session's own δ = 0 readings
//    (RetroReflectionFromSamples) or from a fitted model;
//  - σ (projected area), the visible-normal distribution and its warp are computed from D by
//    quadrature;
//  - at every node of the warped square, for every θi slice, the reflected direction ωo is asked
//    of the SpectrumSource (the session's interpolator of the BRDF, sr⁻¹); the file stores
//    f · cos θo · 4σ(θi) / D(θm), which readers multiply by D / (4σ) (jacobian = 1).
// Where the source has no value the `fallback` source is asked (each counted); a node whose ωo is
// below the surface holds 0. Parallel over θi slices, with progress and cancellation.
#pragma once

#include <cstddef>
#include <cstdint>
#include <map>
#include <optional>
#include <ostream>
#include <string>
#include <vector>

#include "core/call_context.h"
#include "core/export/fill/spectrum_source.h"
#include "core/export/run_control.h"
#include "core/export/session_data.h"
#include "core/export/spectral_rgb.h"
#include "core/status.h"

namespace brdf::exports {

// Retro-reflection: f(θ, θ, φ = 0) (band mean, sr⁻¹) at increasing θ (degrees).
struct RetroProfile {
  std::vector<double> theta_deg;
  std::vector<double> value;
  std::string origin;  // "12 retro-reflection readings", "fitted GGX model", …
};

// The session's readings at δ = 0 (θi = θo within tolerance_deg, φ ignored), averaged per
// distinct θ. kFailedPrecondition when fewer than 3 distinct θ (then use a fitted model).
Result<RetroProfile> RetroReflectionFromSamples(const DerivedSamples& derived,
                                                double tolerance_deg = 0.01);

struct RglOptions {
  std::size_t theta_i_count = 24;  // θi slices, evenly from 0 to theta_i_max_deg
  double theta_i_max_deg = 80;     // the largest θi measured (readers hold the last slice beyond)
  std::size_t sample_res = 48;     // spectra / luminance nodes per side of the warped square
  std::size_t ndf_res = 128;       // ndf and sigma nodes along u_θ
  std::size_t vndf_res = 64;       // vndf nodes per side
  std::string description;         // free text stored in the file
  // When set: an RGB file (field `rgb`, linear sRGB under D65) instead of the spectral one.
  std::optional<SpectralRgbWeights> rgb;
};

struct RglReport {
  std::size_t cells = 0;          // θi slices × nodes of the warped square
  std::size_t interpolated = 0;   // answered by the source
  std::size_t fallback = 0;       // answered by the fallback source
  std::size_t below_horizon = 0;  // ωo below the surface: 0
  std::map<interp::InterpStatus, std::size_t>
      unfilled;             // neither answered: 0 (by the source's why)
  std::size_t clamped = 0;  // RGB: nodes with a negative component set to 0
  std::string retro_origin;
  std::size_t unfilled_total() const;
  std::string Summary() const;
};

// One field of a tensor_file: name, shape, and its values (float32 or uint8).
struct RglField {
  std::string name;
  std::vector<std::uint64_t> shape;
  std::vector<float> f32;        // dtype float32 when bytes is empty
  std::vector<std::uint8_t> u8;  // dtype uint8
  bool is_u8 = false;
};

struct RglExport {
  std::vector<RglField> fields;  // in file order
  RglReport report;
};

// Errors: a bad option or profile (kInvalidArgument, naming it), RGB weights on another grid,
// kCancelled / kTimeout from `ctx`.
Result<RglExport> BuildRgl(const SpectrumSource& source, const SpectrumSource& fallback,
                           const WavelengthGrid& bands, const RetroProfile& retro,
                           const RglOptions& options, const RunControl& control,
                           const CallContext& ctx);

// Writes the tensor_file: "tensor_file\0", version 1.0, the field table, each field's data at an
// 8-byte aligned offset, all little-endian. kIoError when the stream fails.
Status WriteRgl(const std::vector<RglField>& fields, std::ostream& out);

}  // namespace brdf::exports
