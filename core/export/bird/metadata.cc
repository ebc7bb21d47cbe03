#include "core/export/bird/metadata.h"

#include <ctime>

#include "core/export/number_text.h"

namespace brdf::exports {
namespace {

// What the format requires and brdfd does not record.
constexpr const char* kNotRecorded = "not recorded by brdfd";
// A syntactically valid address in the reserved .invalid domain (RFC 2606): no one's mailbox.
constexpr const char* kNoEmail = "not-recorded@brdfd.invalid";

std::string OrNotRecorded(const std::string& text) {
  return text.empty() ? kNotRecorded : text;
}

std::string DatasetId(const BirdProvenance& p) {
  if (!p.session_uuid.empty()) return "urn:uuid:" + p.session_uuid;
  return "urn:x-brdfd:session:" + std::to_string(p.session_id);
}

void WriteProvenance(JsonOut& json, const BirdProvenance& p) {
  json.Key("provenance");
  json.BeginObject();
  json.Field("organization", kNotRecorded);
  json.Key("location");
  json.BeginObject();
  for (const char* key : {"country", "city", "street", "building_nr", "postal_code"}) {
    json.Field(key, kNotRecorded);
  }
  json.EndObject();
  json.Field("email", kNoEmail);
  json.Field("contact_person", kNotRecorded);
  json.Field("comments",
             "brdfd records no organisation, address or contact; the format requires them, so "
             "they say 'not recorded by brdfd' and the email is in the reserved .invalid domain. "
             "Recorded on rig '" +
                 OrNotRecorded(p.rig) + "', session " + std::to_string(p.session_id) + ".");
  json.EndObject();
}

void WriteRange(JsonOut& json, const char* key, const WavelengthGrid& grid) {
  json.Key(key);
  json.BeginObject();
  json.Field("min_value", grid.start_nm);
  json.Field("max_value", grid.last_nm());
  json.Field("unit", "nm");
  json.EndObject();
}

void WriteIllumination(JsonOut& json, const WavelengthGrid& grid) {
  json.Key("illumination_system");
  json.BeginObject();
  json.Field("name", "lamp (broadband, unfiltered)");
  json.Key("source");
  json.BeginObject();
  json.Field("name", kNotRecorded);
  json.Field("type", "broadband lamp");
  json.ValueWithUnit("power", 0, "W");
  WriteRange(json, "wl_range", grid);
  json.EndObject();
  json.Key("beam");
  json.BeginObject();
  json.Field("shape", kNotRecorded);
  json.Key("dimensions");
  json.BeginObject();
  json.ValueWithUnit("area", 0, "mm^2");
  json.EndObject();
  json.EndObject();
  json.Field("comments",
             "brdfd does not record the lamp's model or power nor the beam's shape or area; the "
             "format requires numbers there, so power and area are 0, meaning 'not recorded'. "
             "wl_range is the meter's wavelength range, over which the BRDF was measured.");
  json.EndObject();
}

void WriteDetection(JsonOut& json, const BirdProvenance& p, const WavelengthGrid& grid) {
  json.Key("detection_system");
  json.BeginObject();
  json.Field("name", "spectroradiometer");
  if (!p.meter_model.empty()) json.Field("model", p.meter_model);
  json.Key("sensors");
  json.BeginArray();
  json.BeginObject();
  json.Field("name", p.meter_model.empty() ? "spectroradiometer" : p.meter_model);
  json.Field("type", "spectroradiometer");
  WriteRange(json, "spectral_response_range", grid);
  json.Field("comments", "serial number " + OrNotRecorded(p.meter_serial) + "; model " +
                             OrNotRecorded(p.meter_model) + " (as recorded with the session)");
  json.EndObject();
  json.EndArray();
  json.ValueWithUnit("solid_angle", 0, "sr");
  json.Field("comments",
             "The meter resolves the reflected light spectrally (wavelength_r). Its measuring "
             "field's solid angle is not recorded by brdfd; the format requires a number, so "
             "solid_angle is 0, meaning 'not recorded'.");
  json.EndObject();
}

void WriteInstrumentation(JsonOut& json, const BirdProvenance& p, const WavelengthGrid& grid) {
  json.Key("instrumentation");
  json.BeginObject();
  json.Field("name", "gonioreflectometer run by brdfd" +
                         (p.rig.empty() ? std::string() : " (rig '" + p.rig + "')"));
  json.Field("operation_type", "relative");
  WriteIllumination(json, grid);
  WriteDetection(json, p, grid);
  json.Field("comments",
             "Relative measurement against a white reflectance standard: BRDF = ρw / π · cos θr "
             "/ cos θi · (I − D) / (I0 − D) (docs/geometry.md). The standard is in "
             "metadata.adhoc_section.brdfd.white_standard.");
  json.EndObject();
}

void WriteSoftware(JsonOut& json, const BirdProvenance& p) {
  json.Key("software");
  json.BeginObject();
  json.Field("name", p.software_name);
  json.Field("version", OrNotRecorded(p.software_version));
  json.Field("comments",
             "Recorded the session and wrote this file; the file's version is the writer's, "
             "which may be later than the recording's.");
  json.EndObject();
}

void WriteSample(JsonOut& json, const BirdProvenance& p) {
  json.Key("sample");
  json.BeginObject();
  json.Field("name", !p.sample_name.empty() ? p.sample_name
                     : !p.sample_id.empty() ? p.sample_id
                                            : "session " + std::to_string(p.session_id));
  json.Field("type", OrNotRecorded(p.sample_material));
  json.Field("shape", kNotRecorded);
  json.Key("dimensions");
  json.BeginObject();
  json.EndObject();
  json.Field("origin_location", "the point where the lamp's and the detector's axes meet");
  json.Field("zero_azimuth_location",
             "the sample frame's tangent t at dial position γ = 0 (docs/geometry.md)");
  json.Field("properties_symmetry", p.anisotropic ? "anisotropic" : "isotropic");
  json.Field("comments",
             "id " + OrNotRecorded(p.sample_id) + "; " + OrNotRecorded(p.sample_description));
  json.EndObject();
}

}  // namespace

std::string BirdTimestamp(std::int64_t unix_seconds) {
  const std::time_t t = static_cast<std::time_t>(unix_seconds);
  std::tm utc{};
  gmtime_r(&t, &utc);
  char text[32];
  std::strftime(text, sizeof text, "%Y-%m-%dT%H:%M:%SZ", &utc);
  return text;
}

std::string BirdUncertaintyNote(const BirdReport& facts) {
  if (facts.ubrdf_written) {
    return "uBRDF is the combined standard uncertainty u_c (k = 1, sr^-1) of each reading's "
           "stored budget (docs/uncertainty.md); every written reading has one.";
  }
  std::string note =
      "uBRDF is left out: " + std::to_string(facts.readings - facts.budgeted_readings) +
      " of the " + std::to_string(facts.readings) +
      " written readings have no uncertainty budget (not estimated: recorded "
      "before budgets were stored, or the budget could not be read), and the "
      "format wants a number for every point.";
  return note;
}

namespace {

void WriteWhiteStandard(JsonOut& json, const BirdProvenance& p) {
  json.Key("white_standard");
  json.BeginObject();
  json.Field("id", OrNotRecorded(p.white_standard_id));
  if (p.white_reflectance_is_spectrum) {
    json.Field("reflectance", "a spectrum from its certificate (the plan's sample block)");
  } else {
    json.Field("reflectance", p.white_reflectance);
  }
  if (p.white_reflectance_u.has_value()) {
    json.Field("standard_uncertainty", *p.white_reflectance_u);
    json.Field("standard_uncertainty_from", p.white_reflectance_u_source);
  } else {
    json.Field("standard_uncertainty", kNotRecorded);
  }
  json.EndObject();
}

// brdfd's own record of the session, in its words (metadata.adhoc_section.brdfd).
void WriteAdhocSection(JsonOut& json, const BirdProvenance& p, const BirdReport& facts) {
  json.Key("adhoc_section");
  json.BeginObject();
  json.Key("brdfd");
  json.BeginObject();
  json.Key("session_id");
  json.Integer(p.session_id);
  json.Field("session_name", p.session_name);
  json.Field("session_uuid", OrNotRecorded(p.session_uuid));
  json.Field("rig", OrNotRecorded(p.rig));
  json.Field("plan_name", p.plan_name);
  json.Key("averages");
  json.Integer(p.averages);
  json.Field("meter_model", OrNotRecorded(p.meter_model));
  json.Field("meter_serial", OrNotRecorded(p.meter_serial));
  WriteWhiteStandard(json, p);
  json.Key("readings");
  json.Integer(static_cast<std::int64_t>(facts.readings));
  json.Key("readings_with_budget");
  json.Integer(static_cast<std::int64_t>(facts.budgeted_readings));
  json.Key("brdf_values_clamped_to_zero");
  json.Integer(static_cast<std::int64_t>(facts.clamped_values));
  json.Key("readings_left_out");
  json.BeginArray();
  for (const SkippedReading& s : facts.skipped) {
    json.BeginObject();
    json.Key("reading_id");
    json.Integer(s.reading_id);
    json.Field("reason", s.reason);
    json.EndObject();
  }
  json.EndArray();
  json.Field("plan_json", p.plan_json);
  json.EndObject();
  json.EndObject();
}

std::string Description(const BirdProvenance& p, const WavelengthGrid& grid,
                        const BirdReport& facts) {
  return "Spectral BRDF of " +
         (p.sample_name.empty() ? std::string("the sample") : "'" + p.sample_name + "'") +
         " measured in brdfd session " + std::to_string(p.session_id) + " '" + p.session_name +
         "': " + std::to_string(facts.readings) + " sample readings × " +
         std::to_string(grid.count) + " bands (" + FormatNumber(grid.start_nm) + "–" +
         FormatNumber(grid.last_nm()) + " nm), one point per reading and band.";
}

std::string Comments(const BirdReport& facts) {
  std::string c =
      "Angles in degrees in the sample frame (docs/geometry.md): theta from the normal, phi "
      "the azimuth from the tangent t, in [0, 360). " +
      BirdUncertaintyNote(facts) +
      " The white standard's share of u_c is common to every point (fully correlated); "
      "averaging points does not reduce it. BRDF values below 0 (noise on dim readings) are "
      "written as 0: " +
      std::to_string(facts.clamped_values) +
      ". data.adhoc_variables.reading_id names each "
      "point's reading.";
  return c;
}

}  // namespace

void WriteBirdMetadata(JsonOut& json, const BirdProvenance& p, const WavelengthGrid& grid,
                       const BirdReport& facts) {
  json.Key("metadata");
  json.BeginObject();
  json.Field("schema", kBirdSchemaUrl);
  json.Field("id", DatasetId(p));
  json.Field("type", "BRDF");
  json.Field("timestamp", BirdTimestamp(p.measured_at));
  WriteProvenance(json, p);
  json.Field("description", Description(p, grid, facts));
  json.Field("method", "measurement");
  WriteInstrumentation(json, p, grid);
  WriteSoftware(json, p);
  WriteSample(json, p);
  json.Field("environment", "NA");
  json.Field("comments", Comments(facts) +
                             " environment is 'NA': brdfd records no temperature, humidity or "
                             "pressure.");
  WriteAdhocSection(json, p, facts);
  json.EndObject();
}

}  // namespace brdf::exports
