#include "core/export/bird/writer.h"

#include <algorithm>
#include <cmath>

#include "core/export/bird/json_out.h"
#include "core/export/bird/metadata.h"
#include "core/export/number_text.h"

namespace brdf::exports {
namespace {

// The format's zenith angles lie in [0°, 90°), its azimuths in [0°, 360°).
bool ZenithFits(double theta_deg) {
  return theta_deg >= 0 && theta_deg < 90;
}

double AzimuthIn0To360(double phi_deg) {
  double phi = std::fmod(phi_deg, 360.0);
  if (phi < 0) phi += 360.0;
  return phi >= 360.0 ? 0.0 : phi;  // −1e-17 + 360 rounds to 360
}

// Why a derived sample cannot be written, or "" when it can.
std::string WhyNotWritten(const DerivedSample& s) {
  const Directions& d = s.directions;
  for (double a : {d.theta_i, d.phi_i, d.theta_o, d.phi_o}) {
    if (!std::isfinite(a)) return "a direction is not finite";
  }
  if (!ZenithFits(d.theta_i) || !ZenithFits(d.theta_o)) {
    return "θi " + FormatNumber(d.theta_i) + "° or θo " + FormatNumber(d.theta_o) +
           "° is not in [0°, 90°), which the format's zenith angles must be";
  }
  for (double v : s.values) {
    if (!std::isfinite(v)) return "its BRDF is not finite in some band";
  }
  return "";
}

bool UsableBudget(const std::vector<double>& u, std::size_t bands) {
  return u.size() == bands &&
         std::all_of(u.begin(), u.end(), [](double x) { return std::isfinite(x) && x >= 0; });
}

// The samples to write (indexes into brdf.samples) and the facts the metadata states.
struct Selection {
  std::vector<std::size_t> kept;
  BirdReport facts;
};

Selection Select(const DerivedSamples& brdf, const std::vector<std::vector<double>>& u) {
  Selection s;
  for (std::size_t i = 0; i < brdf.samples.size(); ++i) {
    const DerivedSample& sample = brdf.samples[i];
    if (std::string why = WhyNotWritten(sample); !why.empty()) {
      s.facts.skipped.push_back({sample.reading_id, "reading " + std::to_string(sample.reading_id) +
                                                        " left out: " + why});
      continue;
    }
    s.kept.push_back(i);
    if (UsableBudget(u[i], brdf.grid.count)) ++s.facts.budgeted_readings;
    s.facts.clamped_values += static_cast<std::size_t>(
        std::count_if(sample.values.begin(), sample.values.end(), [](double v) { return v < 0; }));
  }
  s.facts.readings = s.kept.size();
  s.facts.points = s.kept.size() * brdf.grid.count;
  s.facts.ubrdf_written = !s.kept.empty() && s.facts.budgeted_readings == s.kept.size();
  return s;
}

// One column of the data section: {"name": …, "unit": …, "values": [v(sample, band) …]}.
template <typename ValueOf>
void WriteColumn(JsonOut& json, const char* key, const char* name, const char* unit,
                 const DerivedSamples& brdf, const std::vector<std::size_t>& kept, ValueOf value_of,
                 const std::string& comments = "") {
  json.Key(key);
  json.BeginObject();
  if (name != nullptr) json.Field("name", name);
  json.Field("unit", unit);
  json.Key("values");
  json.BeginArray();
  for (std::size_t i : kept) {
    for (std::size_t band = 0; band < brdf.grid.count; ++band) json.Number(value_of(i, band));
  }
  json.EndArray();
  if (!comments.empty()) json.Field("comments", comments);
  json.EndObject();
}

void WriteReadingIds(JsonOut& json, const DerivedSamples& brdf,
                     const std::vector<std::size_t>& kept) {
  json.Key("adhoc_variables");
  json.BeginObject();
  json.Key("reading_id");
  json.BeginObject();
  json.Field("name", "reading_id");
  json.Field("description",
             "The brdfd reading each point comes from (its id in the session); the points of one "
             "reading share its geometry and its uncertainty budget's correlated components.");
  json.Field("unit", "");
  json.Field("type", "integer");
  json.Key("values");
  json.BeginArray();
  for (std::size_t i : kept) {
    for (std::size_t band = 0; band < brdf.grid.count; ++band) {
      json.Integer(brdf.samples[i].reading_id);
    }
  }
  json.EndArray();
  json.EndObject();
  json.EndObject();
}

void WriteData(JsonOut& json, const DerivedSamples& brdf, const std::vector<std::vector<double>>& u,
               const Selection& s, const BirdOptions& options) {
  const auto& samples = brdf.samples;
  const auto report = [&options](double f) {
    if (options.progress) options.progress(f);
  };
  json.Key("data");
  json.BeginObject();
  WriteColumn(json, "theta_i", "theta_i", "deg", brdf, s.kept,
              [&](std::size_t i, std::size_t) { return samples[i].directions.theta_i; });
  WriteColumn(json, "phi_i", "phi_i", "deg", brdf, s.kept, [&](std::size_t i, std::size_t) {
    return AzimuthIn0To360(samples[i].directions.phi_i);
  });
  WriteColumn(json, "theta_r", "theta_r", "deg", brdf, s.kept,
              [&](std::size_t i, std::size_t) { return samples[i].directions.theta_o; });
  WriteColumn(json, "phi_r", "phi_r", "deg", brdf, s.kept, [&](std::size_t i, std::size_t) {
    return AzimuthIn0To360(samples[i].directions.phi_o);
  });
  report(0.3);
  WriteColumn(json, "wavelength_r", "wavelength_r", "nm", brdf, s.kept,
              [&](std::size_t, std::size_t band) { return brdf.grid.at(band); });
  report(0.4);
  WriteColumn(
      json, "BRDF", "BRDF", "sr^-1", brdf, s.kept,
      [&](std::size_t i, std::size_t band) { return std::max(0.0, samples[i].values[band]); },
      "ρw / π · cos θr / cos θi · (I − D) / (I0 − D); " + std::to_string(s.facts.clamped_values) +
          " values below 0 (noise on dim readings) written as 0.");
  report(0.7);
  if (s.facts.ubrdf_written) {
    WriteColumn(
        json, "uBRDF", nullptr, "sr^-1", brdf, s.kept,
        [&](std::size_t i, std::size_t band) { return u[i][band]; }, BirdUncertaintyNote(s.facts));
  }
  report(0.9);
  WriteReadingIds(json, brdf, s.kept);
  json.EndObject();
}

}  // namespace

std::string BirdReport::Summary() const {
  return std::to_string(readings) + " sample readings, " + std::to_string(points) +
         " points; uBRDF " +
         (ubrdf_written ? "written"
                        : "left out (" + std::to_string(readings - budgeted_readings) +
                              " readings without a budget)") +
         "; " + std::to_string(clamped_values) + " BRDF values below 0 written as 0; " +
         std::to_string(skipped.size()) + " readings left out";
}

Result<BirdReport> WriteBird(const BirdProvenance& provenance, const DerivedSamples& brdf,
                             const std::vector<std::vector<double>>& combined_u, std::ostream& out,
                             const BirdOptions& options) {
  if (brdf.quantity != Quantity::kBrdf) {
    return InvalidArgument("a BiRD file holds the BRDF; derive the samples as BRDF, not " +
                           std::string(QuantityName(brdf.quantity)));
  }
  if (combined_u.size() != brdf.samples.size()) {
    return InvalidArgument("combined_u has " + std::to_string(combined_u.size()) + " entries for " +
                           std::to_string(brdf.samples.size()) +
                           " samples; give one per sample (empty: no budget)");
  }
  Selection s = Select(brdf, combined_u);
  if (s.kept.empty()) {
    return FailedPrecondition("no sample reading can be written to a BiRD file" +
                              (s.facts.skipped.empty() ? std::string(" (the session has none)")
                                                       : ": " + s.facts.skipped.front().reason));
  }
  JsonOut json(out);
  json.BeginObject();
  WriteBirdMetadata(json, provenance, brdf.grid, s.facts);
  WriteData(json, brdf, combined_u, s, options);
  json.EndObject();
  BRDF_RETURN_IF_ERROR(json.Finish());
  if (options.progress) options.progress(1.0);
  return std::move(s.facts);
}

}  // namespace brdf::exports
