// A session's readings as the exports see them, and the quantities derived from them
// (docs/geometry.md, "Reflectance and BRDF"). core/ does not depend on storage/, so
// the caller (brdf-export, a gRPC handler) copies storage's ReadingRecords into these plain values.
//
// The derivation matches the daemon's interpolation index (daemon/index_cache.h), so that an
// export and a live query of the same session agree. Per sample reading I:
//   radiance     I − D                                (D: the dark the reading names, if any)
//   reflectance  R = (I − D) / (I0 − D)               (I0: the reference the reading names)
//   BRDF         f = R · ρw / π · cos θi,ref / cos θi (θi,ref: the reference reading's θi;
//                                                      ρw: the session's white reflectance)
// A reading whose quantity cannot be computed (no reference, a reference too dark in a band,
// another wavelength grid, a direction below the surface) is left out with the reason.
// Pure: no I/O.
#pragma once

#include <cstdint>
#include <memory>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "core/interp/interpolator.h"
#include "core/pose.h"
#include "core/spectrum.h"
#include "core/status.h"

namespace brdf::exports {

// What a reading measured: the sample I, the white standard I0, or the dark (ambient) D.
enum class ReadingKind { kSample, kReference, kDark };
const char* ReadingKindName(ReadingKind kind);  // "sample", "reference", "dark"

// One stored reading (storage::ReadingRecord without storage's types).
struct Reading {
  std::int64_t id = 0;
  ReadingKind kind = ReadingKind::kSample;
  Pose pose;               // the pose reached (stage readings, degrees)
  Directions directions;   // θi φi θo φo in the sample frame (degrees)
  Spectrum spectrum;       // radiance as the meter reported it, W·m⁻²·sr⁻¹·nm⁻¹
  int quality_code = 0;    // the meter's quality code (0 = OK)
  bool flagged = false;    // kept but flagged by the quality policy
  int integration_ms = 0;  // 0 = adaptive
  std::optional<std::int64_t> reference_id;  // the I0 this reading is divided by
  std::optional<std::int64_t> dark_id;       // the D subtracted, when measured
};

struct Session {
  std::int64_t id = 0;
  std::string name;
  // ρw of the white standard; nullopt: the paper's RS-3, kWhiteStandardReflectance (0.99).
  std::optional<double> white_reflectance;
  std::vector<Reading> readings;  // in id order (the order they were taken)
};

// ρw as the exports use it: the session's, else kWhiteStandardReflectance.
double WhiteReflectanceOf(const Session& session);

enum class Quantity { kRadiance, kReflectance, kBrdf };
const char* QuantityName(Quantity q);  // "radiance", "reflectance", "brdf"
// The unit of the quantity's values: "W·m⁻²·sr⁻¹·nm⁻¹", "1 (unitless)", "sr⁻¹".
const char* QuantityUnit(Quantity q);
// One sentence defining the quantity, for file headers.
std::string QuantityDefinition(Quantity q);
// kInvalidArgument naming the accepted words.
Result<Quantity> ParseQuantity(std::string_view name);

// One sample reading turned into the quantity.
struct DerivedSample {
  std::int64_t reading_id = 0;
  Directions directions;
  IsoDirection iso;            // ToIsotropic(directions)
  std::vector<double> values;  // one per band of DerivedSamples::grid
};

struct SkippedReading {
  std::int64_t reading_id = 0;
  std::string reason;  // a sentence naming the reading and what was wrong
};

struct DerivedSamples {
  Quantity quantity = Quantity::kBrdf;
  WavelengthGrid grid;                  // the first usable sample reading's grid
  double white_reflectance = 0;         // ρw used (BRDF only)
  std::vector<DerivedSample> samples;   // in reading order
  std::vector<SkippedReading> skipped;  // sample readings left out, in reading order
};

struct DeriveOptions {
  // Leave out readings the quality policy flagged (kept by default, as the daemon does).
  bool exclude_flagged = false;
};

// Derives `quantity` for every sample reading of `session`. Errors: kFailedPrecondition when the
// session has no sample reading ("empty session"), or when none of them could be used (the
// message gives the first reason); kInvalidArgument for a ρw that is not finite and positive.
Result<DerivedSamples> DeriveSamples(const Session& session, Quantity quantity,
                                     const DeriveOptions& options = {});

// The isotropic sample set (θi, θo, φ) for core/interp, ids = reading ids, in sample order.
Result<std::shared_ptr<const interp::SampleSet>> ToSampleSet(const DerivedSamples& derived);

// True when the readings were taken at more than one dial position γ: the session looks
// anisotropic, and an isotropic export (grid, MERL, fits) folds its azimuths together.
bool HasSeveralDialPositions(const Session& session);

}  // namespace brdf::exports
