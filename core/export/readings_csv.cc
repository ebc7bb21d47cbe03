#include "core/export/readings_csv.h"

#include <algorithm>
#include <string>
#include <unordered_map>
#include <vector>

#include "core/csv_field.h"
#include "core/export/grid/text.h"
#include "core/export/number_text.h"

namespace brdf::exports {
namespace {

// At most this many left-out readings are listed one per line; the rest are counted.
constexpr std::size_t kListedSkips = 50;

// A session's readings by id. Sessions come from the store in id order, and are then searched in
// place (brdfd's Data.Export runs a hundred exports of one shared session at once: a hash map of
// 10,000 ids each was ~0.3 MB an export, issue 40); readings in another order get a map.
class ReadingsById {
 public:
  explicit ReadingsById(const std::vector<Reading>& readings) : readings_(readings) {
    const bool ascending = std::adjacent_find(readings.begin(), readings.end(),
                                              [](const Reading& a, const Reading& b) {
                                                return a.id >= b.id;
                                              }) == readings.end();
    if (!ascending) {
      for (const Reading& r : readings) map_.emplace(r.id, &r);
    }
  }
  // The reading of `id`, or null.
  const Reading* Find(std::int64_t id) const {
    if (!map_.empty()) {
      auto it = map_.find(id);
      return it == map_.end() ? nullptr : it->second;
    }
    auto it = std::lower_bound(readings_.begin(), readings_.end(), id,
                               [](const Reading& r, std::int64_t v) { return r.id < v; });
    return it != readings_.end() && it->id == id ? &*it : nullptr;
  }

 private:
  const std::vector<Reading>& readings_;
  std::unordered_map<std::int64_t, const Reading*> map_;  // only when not in id order
};

std::string Header(const Session& session, Quantity quantity, const WavelengthGrid& grid,
                   std::size_t rows, const std::vector<SkippedReading>& skipped) {
  std::string h;
  h += "# brdfd readings export: session " + std::to_string(session.id);
  if (!session.name.empty()) h += " \"" + session.name + "\"";
  h += "\n# quantity: " + std::string(QuantityName(quantity)) + " in " + QuantityUnit(quantity) +
       ": " + QuantityDefinition(quantity) + "\n";
  h += "# units: radiance (the meter's readings I, I0, D) in W·m⁻²·sr⁻¹·nm⁻¹; reflectance "
       "unitless; BRDF in sr⁻¹; angles in degrees; wavelengths in nm\n";
  h += "# radiance is per nm of wavelength, as the PR-650 reports it, at band centres; files of "
       "Psychtoolbox and BrainardLab hold power per band (per 4 nm: 4 × these values)\n";
  if (quantity == Quantity::kRadiance) {
    h += "# rows: every reading (sample, reference = white standard I0, dark = ambient D), "
         "spectral radiance as the meter reported it in W·m⁻²·sr⁻¹·nm⁻¹ (no dark subtracted)\n";
  } else {
    h += "# rows: the sample readings; the reference (I0) and dark (D) readings they name are "
         "rows of the radiance export\n";
  }
  if (quantity == Quantity::kBrdf) {
    h += "# white standard reflectance ρw = " + FormatNumber(WhiteReflectanceOf(session)) +
         (session.white_reflectance.has_value() ? " (the session's)" : " (default: RS-3)") + "\n";
  }
  h += "# pose: alpha_deg, beta_deg, gamma_deg, delta_deg are the holder's α (tilt), β (turn "
       "about the lab vertical), γ (dial about the normal) and the lamp–sample–detector angle δ, "
       "as the stages reported them, in degrees\n";
  h += "# directions: theta_i_deg, phi_i_deg (lamp), theta_o_deg, phi_o_deg (detector) in the "
       "sample frame, degrees: θ from the normal, φ in (−180, 180]\n";
  for (const std::string& line : AngleConventionLines()) h += "# " + line + "\n";
  h += "# quality_code: the meter's quality code (0 = OK, 18 = low light, …); flagged: 1 when the "
       "quality policy kept the reading but flagged it; integration_ms: 0 = adaptive\n";
  h += "# reference_id, dark_id: the id of the reference reading this one is divided by and of "
       "the dark reading subtracted; empty = none\n";
  h += "# integration_note: how the meter changed the integration time to take the reading (e.g. "
       "\"quality 19 (overload): integration halved from 500 to 250 ms\"; integration_ms is the "
       "time used); empty = the plan's\n";
  h += "# spectral columns: headed by wavelength in nm, " + std::to_string(grid.count) +
       " bands from " + FormatNumber(grid.start_nm) + " to " + FormatNumber(grid.last_nm()) +
       " every " + FormatNumber(grid.step_nm) + " nm\n";
  if (quantity != Quantity::kRadiance) {
    h += "# uncertainty columns: u_<λ> after the values, the standard uncertainty (k = 1, " +
         std::string(QuantityUnit(quantity)) +
         ") of each value from the reading's budget (docs/uncertainty.md: combined, shared terms "
         "such as the white standard's included); empty = not estimated for that reading, nan = "
         "undefined in that band\n";
  }
  h += "# rows: " + std::to_string(rows) +
       "; sample readings left out: " + std::to_string(skipped.size()) + "\n";
  for (std::size_t i = 0; i < skipped.size() && i < kListedSkips; ++i) {
    h += "#   left out: " + skipped[i].reason + "\n";
  }
  if (skipped.size() > kListedSkips) {
    h += "#   … and " + std::to_string(skipped.size() - kListedSkips) + " more\n";
  }
  h += "id,kind,alpha_deg,beta_deg,gamma_deg,delta_deg,theta_i_deg,phi_i_deg,theta_o_deg,"
       "phi_o_deg,quality_code,flagged,integration_ms,reference_id,dark_id,integration_note";
  for (std::size_t b = 0; b < grid.count; ++b) {
    h += ',';
    AppendNumber(h, grid.at(b));
  }
  for (std::size_t b = 0; quantity != Quantity::kRadiance && b < grid.count; ++b) {
    h += ",u_";
    AppendNumber(h, grid.at(b));
  }
  h += '\n';
  return h;
}

// `u`: nullptr for a file without u columns (radiance); else the values' uncertainties, empty
// when not estimated (empty fields).
void AppendRow(const Reading& r, std::span<const double> values, std::string& out,
               const std::vector<double>* u = nullptr) {
  out += std::to_string(r.id);
  out += ',';
  out += ReadingKindName(r.kind);
  for (double v : {r.pose.alpha, r.pose.beta, r.pose.gamma, r.pose.delta, r.directions.theta_i,
                   r.directions.phi_i, r.directions.theta_o, r.directions.phi_o}) {
    out += ',';
    AppendNumber(out, v);
  }
  out += ',' + std::to_string(r.quality_code) + ',' + (r.flagged ? "1" : "0") + ',' +
         std::to_string(r.integration_ms) + ',';
  if (r.reference_id.has_value()) out += std::to_string(*r.reference_id);
  out += ',';
  if (r.dark_id.has_value()) out += std::to_string(*r.dark_id);
  out += ',';
  AppendCsvField(out, r.integration_note);
  for (double v : values) {
    out += ',';
    AppendNumber(out, v);
  }
  if (u != nullptr && u->empty()) out.append(values.size(), ',');
  for (std::size_t b = 0; u != nullptr && b < u->size(); ++b) {
    out += ',';
    AppendNumber(out, (*u)[b]);
  }
  out += '\n';
}

// Rows are handed to the stream this many bytes at a time (the stream may be a slow client's:
// brdfd holds no more than this of the text).
constexpr std::size_t kFlushBytes = 64 * 1024;

Status Flush(std::ostream& out, std::string& text) {
  out.write(text.data(), static_cast<std::streamsize>(text.size()));
  text.clear();
  if (!out) return IoError("writing the readings CSV failed: is the disk full or read-only?");
  return Status::Ok();
}

}  // namespace

Result<ReadingsCsvReport> WriteReadingsCsv(const Session& session, Quantity quantity,
                                           std::ostream& out, const DeriveOptions& options) {
  ReadingsCsvReport report;
  std::string text;
  if (quantity == Quantity::kRadiance) {
    if (session.readings.empty()) {
      return FailedPrecondition("session " + std::to_string(session.id) +
                                " has no readings (empty session): nothing to export");
    }
    const WavelengthGrid grid = session.readings.front().spectrum.grid;
    for (const Reading& r : session.readings) {
      if (!(r.spectrum.grid == grid) || r.spectrum.values.size() != grid.count) {
        return InvalidArgument("reading " + std::to_string(r.id) +
                               " is on another wavelength grid than reading " +
                               std::to_string(session.readings.front().id) +
                               "; one CSV holds one grid: export the readings separately");
      }
    }
    report.rows = session.readings.size();
    text = Header(session, quantity, grid, report.rows, {});
    BRDF_RETURN_IF_ERROR(Flush(out, text));
    for (const Reading& r : session.readings) {
      AppendRow(r, r.spectrum.values, text);
      if (text.size() > kFlushBytes) BRDF_RETURN_IF_ERROR(Flush(out, text));
    }
    BRDF_RETURN_IF_ERROR(Flush(out, text));
    return report;
  }

  BRDF_ASSIGN_OR_RETURN(const DerivedSamples derived, DeriveSamples(session, quantity, options));
  return WriteDerivedReadingsCsv(session, quantity, derived, out);
}

Result<ReadingsCsvReport> WriteDerivedReadingsCsv(const Session& session, Quantity quantity,
                                                  const DerivedSamples& derived,
                                                  std::ostream& out) {
  ReadingsCsvReport report;
  const ReadingsById by_id(session.readings);
  report.rows = derived.samples.size();
  report.skipped = derived.skipped;
  std::string text = Header(session, quantity, derived.grid, report.rows, derived.skipped);
  BRDF_RETURN_IF_ERROR(Flush(out, text));
  for (const DerivedSample& s : derived.samples) {
    const Reading* reading = by_id.Find(s.reading_id);
    if (reading == nullptr) {
      return Internal("readings CSV: derived sample of reading " + std::to_string(s.reading_id) +
                      " has no reading in session " + std::to_string(session.id));
    }
    AppendRow(*reading, s.values, text, &s.u);
    if (text.size() > kFlushBytes) BRDF_RETURN_IF_ERROR(Flush(out, text));
  }
  BRDF_RETURN_IF_ERROR(Flush(out, text));
  return report;
}

}  // namespace brdf::exports
