// A session's readings as the exports see them, and the quantity they derive from each sample
// reading. The vocabulary (Reading, ReadingKind, Quantity, SessionReadings) and the derivation
// itself are core/readings' (reading.h, quantity.h, derive.h), the same the daemon's
// interpolation index folds readings through, so an export and a live query of the same session
// agree. The caller (brdf-export, a gRPC handler) loads the session with
// storage/session_readings.h. A reading whose quantity cannot be computed is left out with the
// reason. Pure: no I/O.
#pragma once

#include <cstdint>
#include <memory>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "core/interp/interpolator.h"
#include "core/pose.h"
#include "core/readings/quantity.h"
#include "core/readings/reading.h"
#include "core/spectrum.h"
#include "core/status.h"
#include "core/uncertainty/loaded_budget.h"

namespace brdf::exports {

// The vocabulary, under the names the exports have always used.
using ::brdf::HasSeveralDialPositions;
using ::brdf::ParseQuantity;
using ::brdf::Quantity;
using ::brdf::QuantityDefinition;
using ::brdf::QuantityName;
using ::brdf::QuantityUnit;
using ::brdf::Reading;
using ::brdf::ReadingKind;
using ::brdf::ReadingKindName;
using ::brdf::WhiteReflectanceOf;
using Session = ::brdf::SessionReadings;

// One sample reading turned into the quantity.
struct DerivedSample {
  std::int64_t reading_id = 0;
  Directions directions;
  IsoDirection iso;            // ToIsotropic(directions)
  std::vector<double> values;  // one per band of DerivedSamples::grid
  // The values' standard uncertainties (k = 1, same unit) from the reading's budget: the BRDF's
  // (Reading::brdf_u), the reflectance's (Reading::brdf_u_of_ratio · R / f, NaN where f = 0);
  // empty when the reading has none (not estimated) and for radiance.
  std::vector<double> u;
  // The reading's stored budget of the BRDF as the loaded session keeps it (Reading::budget,
  // shared, not copied): its blend form, which the grid's fill chain blends into a cell's
  // measurement part (core/uncertainty/interpolated.h) and whose independent part its calibration
  // reads, and its white standard's contribution; null for other quantities and readings without
  // one.
  std::shared_ptr<const uncertainty::LoadedBudget> budget;
};

struct SkippedReading {
  std::int64_t reading_id = 0;
  std::string reason;  // a sentence naming the reading and what was wrong
};

struct DerivedSamples {
  Quantity quantity = Quantity::kBrdf;
  WavelengthGrid grid;                  // the session's grid: every derived sample is on it
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

}  // namespace brdf::exports
