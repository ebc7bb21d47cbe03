// A session's sample readings as a BiRD universal BRDF file (Lanevski et al., Color Res. Appl.
// 47(5), 2022; the BiRD project's JSON schema v1.0, draft 2020-12). docs/bird-format.md says
// what each field holds and how brdfd fills it. In short:
//   metadata   the session's provenance: its id and time, the instrument (the meter's model and
//              serial as recorded), the sample and white standard (ρw and u(ρw)), the plan, the
//              software; what brdfd does not record is said to be so (docs/bird-format.md);
//   data       one point per (sample reading, band): theta_i, phi_i, theta_r, phi_r (degrees,
//              the sample frame of docs/geometry.md, azimuths in [0°, 360°)), wavelength_r (nm:
//              the meter resolves the reflected light), BRDF (sr⁻¹) and uBRDF (sr⁻¹, the
//              combined standard uncertainty u_c, k = 1, of the reading's stored budget), and the
//              ad hoc variable reading_id (which reading each point came from).
// uBRDF is written only when every written reading has a budget: the format wants a number for
// every point and has no "unknown". Otherwise it is left out and the file's comments say which
// readings had none. A BRDF below 0 (noise on a dim reading) is written as 0, as the format
// asks, and counted. Readings whose θi or θo is not below 90° are left out with the reason.
// The arrays are written as they are made (json_out.h), never held whole: a 50,000-reading
// session of 401 bands is 20 million points. Pure: writes to the std::ostream it is given.
#pragma once

#include <cstdint>
#include <functional>
#include <optional>
#include <ostream>
#include <string>
#include <vector>

#include "core/export/session_data.h"
#include "core/status.h"

namespace brdf::exports {

// The BiRD schema a file follows (metadata.schema).
inline constexpr const char* kBirdSchemaUrl =
    "https://raw.githubusercontent.com/BiRD-project/BiRD_view/master/BRDF_JSON_schema/"
    "brdf_json_schema_v1.0.json";

// What the session's records say of where its readings came from. Empty text: not recorded.
struct BirdProvenance {
  std::int64_t session_id = 0;
  std::string session_name;
  std::string session_uuid;      // metadata.id is urn:uuid:<uuid> when set
  std::string rig;               // the rig that recorded the session
  std::int64_t measured_at = 0;  // Unix seconds: when the session started (else was created)
  std::string plan_name;
  std::string plan_json;  // the stored plan, written as text in metadata.adhoc_section
  bool anisotropic = false;
  int averages = 0;  // the plan's averaging count; 0: not said
  // The sample (the plan's sample block).
  std::string sample_id;
  std::string sample_name;
  std::string sample_material;
  std::string sample_description;
  // The white standard: its id, ρw (a number, or a certificate's spectrum), and u(ρw) (k = 1).
  std::string white_standard_id;
  double white_reflectance = 0.99;
  bool white_reflectance_is_spectrum = false;
  std::optional<double> white_reflectance_u;  // nullopt: not recorded with the session
  // How u(ρw) was found: "plan" (its sample block) or "budgets" (from the stored budgets).
  std::string white_reflectance_u_source;
  // The spectroradiometer as recorded with the session.
  std::string meter_model;
  std::string meter_serial;
  // The software that recorded and wrote it.
  std::string software_name = "brdfd";
  std::string software_version;
};

struct BirdReport {
  std::size_t readings = 0;           // sample readings written
  std::size_t points = 0;             // readings × bands
  std::size_t budgeted_readings = 0;  // of those, with a usable budget
  bool ubrdf_written = false;
  std::size_t clamped_values = 0;       // BRDF values below 0 written as 0
  std::vector<SkippedReading> skipped;  // sample readings left out, with the reason
  std::string Summary() const;
};

struct BirdOptions {
  // Called with the fraction done (0 … 1) as the columns are written; may be empty.
  std::function<void(double)> progress;
};

// Writes the file for `brdf` (DeriveSamples(session, kBrdf, …)). `combined_u` holds, for each
// derived sample in the same order, the combined standard uncertainty of its BRDF per band
// (the stored budget's u_c), or an empty vector when the reading has none; a vector of another
// size than the grid's, or with a negative or non-finite value, counts as none. Errors:
// kInvalidArgument when `brdf` is not the BRDF or `combined_u` does not have one entry per
// sample; kFailedPrecondition when no sample reading can be written (the first reason given);
// kIoError when the stream fails.
Result<BirdReport> WriteBird(const BirdProvenance& provenance, const DerivedSamples& brdf,
                             const std::vector<std::vector<double>>& combined_u, std::ostream& out,
                             const BirdOptions& options = {});

}  // namespace brdf::exports
