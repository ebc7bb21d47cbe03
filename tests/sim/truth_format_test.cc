// `brdf-sim truth` output, in-process: the text and JSON forms carry the true BRDF exactly.
#include <gtest/gtest.h>

#include <cstdlib>
#include <limits>
#include <sstream>
#include <string>
#include <vector>

#include "core/analytic_brdf.h"
#include "tools/brdf-sim/optics/optics.h"
#include "tools/brdf-sim/optics/truth.h"

namespace brdf::sim {
namespace {

// The numbers of a JSON array named `key` (a minimal reader for our own flat output).
std::vector<double> JsonArray(const std::string& json, const std::string& key) {
  std::vector<double> out;
  const std::size_t start = json.find("\"" + key + "\":[");
  if (start == std::string::npos) return out;
  const char* p = json.c_str() + start + key.size() + 4;
  while (*p != ']' && *p != '\0') {
    char* end = nullptr;
    out.push_back(std::strtod(p, &end));
    p = end;
    if (*p == ',') ++p;
  }
  return out;
}

TEST(TruthFormatTest, TextHasOneBandPerLineAndRoundTrips) {
  TruthQuery q;
  q.directions = {35, 0, 50, 150};
  std::istringstream in(FormatTruth(q));
  std::string line;
  std::getline(in, line);
  EXPECT_EQ(line.rfind("#", 0), 0u) << "first line is a comment: " << line;
  const auto truth = TrueBrdf(q.directions);
  const auto grid = WavelengthGrid::Pr650();
  std::size_t k = 0;
  double nm = 0, value = 0;
  while (in >> nm >> value) {
    ASSERT_LT(k, grid.count);
    EXPECT_EQ(nm, grid.at(k));
    EXPECT_EQ(value, truth[k]);
    ++k;
  }
  EXPECT_EQ(k, grid.count);
}

// `brdf-sim --meter cs2000 truth ...`: the truth on the meter's grid, 401 bands every 1 nm.
TEST(TruthFormatTest, TheTruthIsOnTheMetersGrid) {
  TruthQuery q;
  q.directions = {35, 0, 50, 150};
  q.json = true;
  const WavelengthGrid cs2000{380, 1, 401};
  const std::string json = FormatTruth(q, SampleMaterial(false, false), cs2000);
  const auto nm = JsonArray(json, "wavelength_nm");
  const auto brdf = JsonArray(json, "brdf");
  ASSERT_EQ(nm.size(), 401u);
  ASSERT_EQ(brdf.size(), 401u);
  EXPECT_EQ(nm.front(), 380);
  EXPECT_EQ(nm[1], 381);
  EXPECT_EQ(nm.back(), 780);
  const std::vector<double> truth =
      SampleMaterial(false, false).EvaluateSpectrum(q.directions, cs2000);
  for (std::size_t k = 0; k < truth.size(); ++k) EXPECT_EQ(brdf[k], truth[k]) << k;
}

TEST(TruthFormatTest, JsonCarriesDirectionsAndSpectrum) {
  TruthQuery q;
  q.directions = {20, 30, 40, 250};
  q.anisotropic = true;
  q.json = true;
  const std::string json = FormatTruth(q);
  EXPECT_NE(json.find("\"anisotropic\":true"), std::string::npos);
  EXPECT_NE(json.find("\"phi_i\":30"), std::string::npos);
  const auto nm = JsonArray(json, "wavelength_nm");
  const auto brdf = JsonArray(json, "brdf");
  EXPECT_EQ(brdf, TrueBrdf(q.directions, true));
  ASSERT_EQ(nm.size(), 101u);
  EXPECT_EQ(nm.front(), 380);
  EXPECT_EQ(nm.back(), 780);
}

TEST(TruthFormatTest, GlossySampleIsAnalyticGlossyAndNamesItself) {
  TruthQuery q;
  q.directions = {42.5, 0, 42.5, 177.5};
  q.glossy = true;
  q.json = true;
  const std::string json = FormatTruth(q);
  EXPECT_NE(json.find("\"sample\":\"glossy\""), std::string::npos) << json;
  const auto brdf = JsonArray(json, "brdf");
  EXPECT_EQ(brdf, AnalyticBrdf::Glossy().EvaluateSpectrum(q.directions, WavelengthGrid::Pr650()));
  // Near the mirror direction the glossy lobe is several times the paint's.
  EXPECT_GT(brdf[43], 3 * TrueBrdf(q.directions)[43]);
  q.anisotropic = true;
  EXPECT_EQ(ValidateTruthQuery(q).code(), StatusCode::kInvalidArgument);
  EXPECT_NE(ValidateTruthQuery(q).message().find("--glossy"), std::string::npos);
}

TEST(TruthFormatTest, RejectsNonFiniteAngles) {
  TruthQuery q;
  q.directions.theta_o = std::numeric_limits<double>::quiet_NaN();
  EXPECT_EQ(ValidateTruthQuery(q).code(), StatusCode::kInvalidArgument);
  EXPECT_NE(ValidateTruthQuery(q).message().find("--theta-o"), std::string::npos);
}

}  // namespace
}  // namespace brdf::sim
