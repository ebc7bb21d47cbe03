#include "export_test_util.h"

#include <gtest/gtest.h>

#include <fstream>
#include <sstream>

#include "core/export/synthetic_session.h"

namespace brdf::exports::testing {

std::string ReadFile(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  if (!in) return "";
  std::ostringstream s;
  s << in.rdbuf();
  return s.str();
}

CieTables LoadCie() {
  CieTables t;
  const std::string cmf_text = ReadFile("/usr/share/colord/cmf/CIE1931-2deg-XYZ.cmf");
  const std::string d65_text = ReadFile("/usr/share/colord/illuminant/CIE-D65.sp");
  if (cmf_text.empty() || d65_text.empty()) {
    ADD_FAILURE() << "CIE tables missing under /usr/share/colord: install colord-data";
    return t;
  }
  Result<SpectralTable> cmf = ParseSpectralTable(cmf_text);
  Result<SpectralTable> d65 = ParseSpectralTable(d65_text);
  EXPECT_TRUE(cmf.ok() && d65.ok());
  if (!cmf.ok() || !d65.ok()) return t;
  Result<ColorMatchingFunctions> c = ColorMatchingFunctionsFromTable(*cmf);
  Result<Spectrum> s = d65->SetAsSpectrum(0);
  EXPECT_TRUE(c.ok() && s.ok());
  if (c.ok()) t.cmf = *c;
  if (s.ok()) t.d65 = *s;
  return t;
}

SpectralRgbWeights D65Weights(const WavelengthGrid& grid) {
  const CieTables cie = LoadCie();
  Result<SpectralRgbWeights> w = SpectralRgbWeights::Make(grid, cie.d65, cie.cmf);
  EXPECT_TRUE(w.ok()) << w.status().ToString();
  return *w;
}

std::vector<std::vector<std::string>> CsvRows(const std::string& text) {
  std::vector<std::vector<std::string>> rows;
  std::istringstream in(text);
  std::string line;
  while (std::getline(in, line)) {
    if (line.empty() || line[0] == '#') continue;
    std::vector<std::string> fields;
    std::string field;
    std::istringstream ls(line);
    while (std::getline(ls, field, ',')) fields.push_back(field);
    if (!line.empty() && line.back() == ',') fields.emplace_back();
    rows.push_back(std::move(fields));
  }
  return rows;
}

std::vector<std::string> CommentLines(const std::string& text) {
  std::vector<std::string> out;
  std::istringstream in(text);
  std::string line;
  while (std::getline(in, line)) {
    if (!line.empty() && line[0] == '#') out.push_back(line);
  }
  return out;
}

std::optional<PaintGridSamples> PaintLikeGridSamples() {
  SyntheticSessionOptions o;
  o.grid = {380, 40, 11};
  Result<Session> session = SyntheticSession(AnalyticBrdf::PaintLike(), o);
  EXPECT_TRUE(session.ok()) << session.status().ToString();
  if (!session.ok()) return std::nullopt;
  Result<DerivedSamples> derived = DeriveSamples(*session, Quantity::kBrdf);
  EXPECT_TRUE(derived.ok()) << derived.status().ToString();
  if (!derived.ok()) return std::nullopt;
  Result<std::shared_ptr<const interp::SampleSet>> set = ToSampleSet(*derived);
  EXPECT_TRUE(set.ok()) << set.status().ToString();
  if (!set.ok()) return std::nullopt;
  return PaintGridSamples{std::move(*derived), std::move(*set)};
}

}  // namespace brdf::exports::testing
