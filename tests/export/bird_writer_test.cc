// The BiRD universal BRDF writer (core/export/bird/writer.h): the file parses as JSON, holds the
// fields the BiRD schema requires with the types and ranges it asks (angles in [0°, 90°) and
// [0°, 360°), BRDF and uBRDF ≥ 0, arrays of one length), writes uBRDF only when every reading
// has a budget, and refuses what it cannot write. The file is parsed with protobuf's JSON parser
// into a google.protobuf.Struct. tests/python/test_export_live.py checks a daemon's file against
// tests/python/bird_required.schema.json with python3-jsonschema.
#include <google/protobuf/struct.pb.h>
#include <google/protobuf/util/json_util.h>
#include <gtest/gtest.h>

#include <cmath>
#include <sstream>
#include <string>
#include <vector>

#include "core/export/bird/json_out.h"
#include "core/export/bird/metadata.h"
#include "core/export/bird/writer.h"

namespace brdf::exports {
namespace {

using google::protobuf::ListValue;
using google::protobuf::Struct;
using google::protobuf::Value;

DerivedSample MakeSample(std::int64_t id, Directions d, std::vector<double> values) {
  DerivedSample s;
  s.reading_id = id;
  s.directions = d;
  s.values = std::move(values);
  return s;
}

// Three readings on a 4-band grid; reading 12's azimuths are negative and its first band is
// below 0 (noise on a dim reading).
DerivedSamples ThreeReadings() {
  DerivedSamples d;
  d.quantity = Quantity::kBrdf;
  d.grid = {400, 100, 4};
  d.white_reflectance = 0.99;
  d.samples.push_back(MakeSample(11, {30, 0, 45, 180}, {0.10, 0.20, 0.30, 0.40}));
  d.samples.push_back(MakeSample(12, {10, -90, 60, -30}, {-0.001, 0.02, 0.03, 0.04}));
  d.samples.push_back(MakeSample(13, {0, 0, 0, 0}, {0.31, 0.32, 0.33, 0.34}));
  return d;
}

std::vector<std::vector<double>> Budgets() {
  return {{0.001, 0.002, 0.003, 0.004}, {0.0005, 0.0006, 0.0007, 0.0008}, {0.01, 0.01, 0.01, 0.01}};
}

BirdProvenance Provenance() {
  BirdProvenance p;
  p.session_id = 7;
  p.session_name = "paint \"A\"\nsecond line";
  p.session_uuid = "123e4567-e89b-42d3-a456-426614174000";
  p.rig = "sim";
  p.measured_at = 1796554203;  // 2026-12-06T10:50:03Z
  p.sample_name = "red paint";
  p.sample_material = "paint";
  p.white_standard_id = "RS-3 #1187";
  p.white_reflectance_u = 0.0058;
  p.white_reflectance_u_source = "plan";
  p.meter_model = "PR-650";
  p.meter_serial = "60954101";
  p.software_version = "0.1.0";
  return p;
}

struct Written {
  Result<BirdReport> report = Internal("unset");
  Struct json;
  bool parsed = false;
};

Written Write(const DerivedSamples& d, const std::vector<std::vector<double>>& u) {
  Written w;
  std::ostringstream out;
  w.report = WriteBird(Provenance(), d, u, out);
  if (w.report.ok()) {
    const auto parsed = google::protobuf::util::JsonStringToMessage(out.str(), &w.json);
    w.parsed = parsed.ok();
    EXPECT_TRUE(w.parsed) << parsed.ToString() << "\n" << out.str().substr(0, 4000);
  }
  return w;
}

const Value& At(const Struct& s, const std::string& key) {
  static const Value kNull;
  auto it = s.fields().find(key);
  EXPECT_NE(it, s.fields().end()) << "missing key " << key;
  return it == s.fields().end() ? kNull : it->second;
}

const Struct& Obj(const Struct& s, const std::string& key) {
  return At(s, key).struct_value();
}

std::vector<double> Values(const Struct& data, const std::string& column) {
  std::vector<double> out;
  const ListValue& list = At(Obj(data, column), "values").list_value();
  for (const Value& v : list.values()) {
    EXPECT_EQ(v.kind_case(), Value::kNumberValue) << column;
    out.push_back(v.number_value());
  }
  return out;
}

TEST(BirdWriter, MetadataHoldsTheRequiredFieldsWithTheirTypes) {
  Written w = Write(ThreeReadings(), Budgets());
  ASSERT_TRUE(w.report.ok()) << w.report.status().message();
  ASSERT_TRUE(w.parsed);
  ASSERT_EQ(w.json.fields().size(), 2u);
  const Struct& m = Obj(w.json, "metadata");
  for (const char* key : {"schema", "id", "type", "timestamp", "description", "method"}) {
    EXPECT_EQ(At(m, key).kind_case(), Value::kStringValue) << key;
  }
  EXPECT_EQ(At(m, "schema").string_value(), kBirdSchemaUrl);
  EXPECT_EQ(At(m, "id").string_value(), "urn:uuid:123e4567-e89b-42d3-a456-426614174000");
  EXPECT_EQ(At(m, "type").string_value(), "BRDF");
  EXPECT_EQ(At(m, "timestamp").string_value(), "2026-12-06T10:50:03Z");
  EXPECT_EQ(At(m, "method").string_value(), "measurement");
  const Struct& prov = Obj(m, "provenance");
  for (const char* key : {"organization", "email", "contact_person"}) {
    EXPECT_EQ(At(prov, key).kind_case(), Value::kStringValue) << key;
  }
  EXPECT_NE(At(prov, "email").string_value().find('@'), std::string::npos);
  for (const char* key : {"country", "city", "street", "building_nr", "postal_code"}) {
    EXPECT_EQ(At(Obj(prov, "location"), key).kind_case(), Value::kStringValue) << key;
  }
  const Struct& inst = Obj(m, "instrumentation");
  EXPECT_EQ(At(inst, "operation_type").string_value(), "relative");
  const Struct& illum = Obj(inst, "illumination_system");
  EXPECT_EQ(At(Obj(Obj(illum, "source"), "power"), "unit").string_value(), "W");
  EXPECT_EQ(At(Obj(Obj(illum, "source"), "wl_range"), "max_value").number_value(), 700);
  EXPECT_EQ(At(Obj(Obj(Obj(illum, "beam"), "dimensions"), "area"), "unit").string_value(), "mm^2");
  const Struct& det = Obj(inst, "detection_system");
  EXPECT_EQ(At(det, "model").string_value(), "PR-650");
  ASSERT_EQ(At(det, "sensors").list_value().values_size(), 1);
  EXPECT_EQ(At(Obj(det, "solid_angle"), "unit").string_value(), "sr");
  EXPECT_EQ(At(Obj(m, "software"), "name").string_value(), "brdfd");
  EXPECT_EQ(At(Obj(m, "software"), "version").string_value(), "0.1.0");
  const Struct& sample = Obj(m, "sample");
  EXPECT_EQ(At(sample, "name").string_value(), "red paint");
  EXPECT_EQ(At(sample, "type").string_value(), "paint");
  for (const char* key : {"shape", "zero_azimuth_location"}) {
    EXPECT_EQ(At(sample, key).kind_case(), Value::kStringValue) << key;
  }
  EXPECT_EQ(At(sample, "dimensions").kind_case(), Value::kStructValue);
  EXPECT_EQ(At(m, "environment").string_value(), "NA");
  const Struct& brdfd = Obj(Obj(m, "adhoc_section"), "brdfd");
  EXPECT_EQ(At(brdfd, "session_name").string_value(), "paint \"A\"\nsecond line");
  EXPECT_EQ(At(brdfd, "meter_serial").string_value(), "60954101");
  EXPECT_EQ(At(Obj(brdfd, "white_standard"), "id").string_value(), "RS-3 #1187");
  EXPECT_DOUBLE_EQ(At(Obj(brdfd, "white_standard"), "standard_uncertainty").number_value(), 0.0058);
  EXPECT_DOUBLE_EQ(At(Obj(brdfd, "white_standard"), "reflectance").number_value(), 0.99);
}

TEST(BirdWriter, OnePointPerReadingAndBandWithinTheFormatsRanges) {
  Written w = Write(ThreeReadings(), Budgets());
  ASSERT_TRUE(w.report.ok() && w.parsed);
  const Struct& data = Obj(w.json, "data");
  const std::vector<std::string> columns = {"theta_i",      "phi_i", "theta_r", "phi_r",
                                            "wavelength_r", "BRDF",  "uBRDF"};
  for (const std::string& c : columns) {
    EXPECT_EQ(Values(data, c).size(), 12u) << c;
    EXPECT_EQ(At(Obj(data, c), "unit").kind_case(), Value::kStringValue) << c;
  }
  for (const char* c : {"theta_i", "phi_i", "theta_r", "phi_r"}) {
    EXPECT_EQ(At(Obj(data, c), "unit").string_value(), "deg");
  }
  EXPECT_EQ(At(Obj(data, "BRDF"), "unit").string_value(), "sr^-1");
  EXPECT_EQ(At(Obj(data, "uBRDF"), "unit").string_value(), "sr^-1");
  for (const char* c : {"theta_i", "theta_r"}) {
    for (double v : Values(data, c)) EXPECT_TRUE(v >= 0 && v < 90) << c << " " << v;
  }
  for (const char* c : {"phi_i", "phi_r"}) {
    for (double v : Values(data, c)) EXPECT_TRUE(v >= 0 && v < 360) << c << " " << v;
  }
  for (const char* c : {"BRDF", "uBRDF", "wavelength_r"}) {
    for (double v : Values(data, c)) EXPECT_GE(v, 0) << c;
  }
  // Reading 12 (points 4–7): φi −90° is 270°, φo −30° is 330°; its −0.001 is written as 0.
  EXPECT_EQ(Values(data, "phi_i")[4], 270);
  EXPECT_EQ(Values(data, "phi_r")[7], 330);
  EXPECT_EQ(Values(data, "theta_r")[5], 60);
  EXPECT_EQ(Values(data, "BRDF")[4], 0);
  EXPECT_DOUBLE_EQ(Values(data, "BRDF")[5], 0.02);
  EXPECT_EQ(Values(data, "wavelength_r"),
            (std::vector<double>{400, 500, 600, 700, 400, 500, 600, 700, 400, 500, 600, 700}));
  EXPECT_DOUBLE_EQ(Values(data, "uBRDF")[3], 0.004);
  EXPECT_DOUBLE_EQ(Values(data, "uBRDF")[6], 0.0007);
  EXPECT_EQ(Values(Obj(data, "adhoc_variables"), "reading_id")[8], 13);
  EXPECT_EQ(w.report->readings, 3u);
  EXPECT_EQ(w.report->points, 12u);
  EXPECT_EQ(w.report->clamped_values, 1u);
  EXPECT_TRUE(w.report->ubrdf_written);
}

TEST(BirdWriter, UbrdfIsLeftOutWhenAReadingHasNoBudgetAndTheFileSaysSo) {
  std::vector<std::vector<double>> u = Budgets();
  u[1].clear();                      // no budget
  u[2] = {0.01, -0.01, 0.01, 0.01};  // unusable: counts as none
  Written w = Write(ThreeReadings(), u);
  ASSERT_TRUE(w.report.ok() && w.parsed);
  const Struct& data = Obj(w.json, "data");
  EXPECT_EQ(data.fields().count("uBRDF"), 0u);
  EXPECT_EQ(Values(data, "BRDF").size(), 12u);
  EXPECT_FALSE(w.report->ubrdf_written);
  EXPECT_EQ(w.report->budgeted_readings, 1u);
  const std::string comments = At(Obj(w.json, "metadata"), "comments").string_value();
  EXPECT_NE(comments.find("uBRDF is left out: 2 of the 3"), std::string::npos) << comments;
}

TEST(BirdWriter, ReadingsOutsideTheFormatsAnglesAreLeftOutWithTheReason) {
  DerivedSamples d = ThreeReadings();
  d.samples[0].directions.theta_o = 90;
  Written w = Write(d, Budgets());
  ASSERT_TRUE(w.report.ok() && w.parsed);
  ASSERT_EQ(w.report->skipped.size(), 1u);
  EXPECT_EQ(w.report->skipped[0].reading_id, 11);
  EXPECT_NE(w.report->skipped[0].reason.find("θo 90°"), std::string::npos);
  EXPECT_EQ(Values(Obj(w.json, "data"), "theta_r").size(), 8u);
  const Struct& brdfd = Obj(Obj(Obj(w.json, "metadata"), "adhoc_section"), "brdfd");
  EXPECT_EQ(At(brdfd, "readings_left_out").list_value().values_size(), 1);
}

TEST(BirdWriter, RefusesWhatItCannotWrite) {
  std::ostringstream out;
  DerivedSamples none = ThreeReadings();
  for (DerivedSample& s : none.samples) s.directions.theta_i = 95;
  Result<BirdReport> r = WriteBird(Provenance(), none, Budgets(), out);
  EXPECT_EQ(r.status().code(), StatusCode::kFailedPrecondition);
  EXPECT_NE(r.status().message().find("reading 11"), std::string::npos);

  DerivedSamples reflectance = ThreeReadings();
  reflectance.quantity = Quantity::kReflectance;
  EXPECT_EQ(WriteBird(Provenance(), reflectance, Budgets(), out).status().code(),
            StatusCode::kInvalidArgument);
  EXPECT_EQ(WriteBird(Provenance(), ThreeReadings(), {{}}, out).status().code(),
            StatusCode::kInvalidArgument);

  DerivedSamples nan = ThreeReadings();
  nan.samples[2].values[1] = std::nan("");
  Written w = Write(nan, Budgets());
  ASSERT_TRUE(w.report.ok() && w.parsed);
  EXPECT_EQ(w.report->readings, 2u);
}

TEST(BirdWriter, AFailingStreamIsAnIoError) {
  std::ostringstream out;
  out.setstate(std::ios::badbit);
  EXPECT_EQ(WriteBird(Provenance(), ThreeReadings(), Budgets(), out).status().code(),
            StatusCode::kIoError);
}

TEST(JsonOut, EscapesTextAndRefusesNumbersJsonCannotHold) {
  std::ostringstream out;
  JsonOut json(out);
  json.BeginObject();
  json.Field("a", "x\"y\\z\n\x01");
  json.Key("b");
  json.BeginArray();
  json.Number(1.5);
  json.Integer(-2);
  json.EndArray();
  json.EndObject();
  ASSERT_TRUE(json.Finish().ok());
  EXPECT_EQ(out.str(), "{\"a\":\"x\\\"y\\\\z\\n\\u0001\",\"b\":[1.5,-2]}\n");

  std::ostringstream nan_out;
  JsonOut nan_json(nan_out);
  nan_json.BeginArray();
  nan_json.Number(std::nan(""));
  nan_json.EndArray();
  EXPECT_EQ(nan_json.Finish().code(), StatusCode::kInvalidArgument);
}

}  // namespace
}  // namespace brdf::exports
