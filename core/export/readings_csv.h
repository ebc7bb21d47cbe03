// The readings of a session as CSV, one row per reading, with a '#' comment block that documents
// the quantity, units and angle convention so that the file explains itself:
//   id,kind,alpha_deg,beta_deg,gamma_deg,delta_deg,theta_i_deg,phi_i_deg,theta_o_deg,phi_o_deg,
//   quality_code,flagged,integration_ms,reference_id,dark_id,integration_note,<λ1>,<λ2>,…
//   [,u_<λ1>,u_<λ2>,…]   (reflectance and BRDF only)
// Spectral columns are headed by wavelength in nm. The u_<λ> columns (after the values) hold each
// value's standard uncertainty (k = 1, the same unit) from the reading's budget
// (docs/uncertainty.md): empty when the reading has none (not estimated: a session recorded before
// budgets, or without [uncertainty]), nan where it is undefined. Readers that take the numeric
// headers as the spectrum keep working: the u columns' headers are not numbers
// (readings_csv_reader.h reads both layouts). integration_note says how the meter changed the
// integration time (Reading.integration_note; quoted when it holds a comma), empty when it did not.
//   radiance:            every reading (sample, reference, dark), raw as the meter reported it
//                        (no dark subtracted: dark_id names the dark reading to subtract);
//   reflectance, brdf:   the sample readings whose quantity can be computed (session_data.h);
//                        the others are listed in the header with the reason.
#pragma once

#include <ostream>
#include <vector>

#include "core/export/session_data.h"
#include "core/status.h"

namespace brdf::exports {

struct ReadingsCsvReport {
  std::size_t rows = 0;
  std::vector<SkippedReading> skipped;  // sample readings left out (reflectance, brdf)
};

// Errors: kFailedPrecondition for a session without readings (or, for reflectance/brdf, without
// a usable sample reading); kInvalidArgument when the readings to write are not all on one
// wavelength grid (radiance; the message names the reading); kIoError when the stream fails.
Result<ReadingsCsvReport> WriteReadingsCsv(const Session& session, Quantity quantity,
                                           std::ostream& out, const DeriveOptions& options = {});

// The same file (reflectance or BRDF) from samples derived beforehand, `derived` =
// DeriveSamples(session, quantity, options): for callers that share one derivation between
// several exports of a session (brdfd's Data.Export, daemon/api/export_loads.h).
Result<ReadingsCsvReport> WriteDerivedReadingsCsv(const Session& session, Quantity quantity,
                                                  const DerivedSamples& derived, std::ostream& out);

}  // namespace brdf::exports
