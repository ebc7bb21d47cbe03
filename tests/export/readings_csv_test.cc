// The readings CSV: a header that documents units, one row per reading, values that read back,
// and the derived quantities equal to the BRDF the synthetic session was measured on.
#include "core/export/readings_csv.h"

#include <gtest/gtest.h>

#include <cmath>
#include <sstream>

#include "core/export/synthetic_session.h"
#include "export_test_util.h"

namespace brdf::exports {
namespace {

using testing::CommentLines;
using testing::CsvRows;

Session SmallSession(bool with_dark = true) {
  SyntheticSessionOptions o;
  o.poses.delta_stop_deg = 22.5;  // 3 detector positions: a few hundred poses
  o.with_dark = with_dark;
  Result<Session> s = SyntheticSession(AnalyticBrdf::PaintLike(), o);
  EXPECT_TRUE(s.ok()) << s.status().ToString();
  return *s;
}

std::string Joined(const std::vector<std::string>& lines) {
  std::string s;
  for (const auto& l : lines) s += l + "\n";
  return s;
}

TEST(ReadingsCsv, HeaderDocumentsUnitsAnglesAndQuantity) {
  const Session session = SmallSession();
  for (Quantity q : {Quantity::kRadiance, Quantity::kReflectance, Quantity::kBrdf}) {
    std::ostringstream out;
    ASSERT_TRUE(WriteReadingsCsv(session, q, out).ok());
    const std::string comments = Joined(CommentLines(out.str()));
    EXPECT_NE(comments.find(std::string("quantity: ") + QuantityName(q)), std::string::npos);
    EXPECT_NE(comments.find(QuantityUnit(q)), std::string::npos) << QuantityName(q);
    EXPECT_NE(comments.find("W·m⁻²·sr⁻¹·nm⁻¹"), std::string::npos);  // radiance, always named
    EXPECT_NE(comments.find("degrees"), std::string::npos);
    EXPECT_NE(comments.find("geometry.md"), std::string::npos);
    EXPECT_NE(comments.find("wavelength in nm"), std::string::npos);
    if (q == Quantity::kBrdf) {
      EXPECT_NE(comments.find("ρw = 0.99"), std::string::npos);
      EXPECT_NE(comments.find("cos θi,ref / cos θi"), std::string::npos);
    }
    if (q == Quantity::kReflectance) {
      EXPECT_NE(comments.find("(I0(λ) − D(λ))"), std::string::npos);
    }

    const auto rows = CsvRows(out.str());
    ASSERT_FALSE(rows.empty());
    const std::vector<std::string> want = {"id",
                                           "kind",
                                           "alpha_deg",
                                           "beta_deg",
                                           "gamma_deg",
                                           "delta_deg",
                                           "theta_i_deg",
                                           "phi_i_deg",
                                           "theta_o_deg",
                                           "phi_o_deg",
                                           "quality_code",
                                           "flagged",
                                           "integration_ms",
                                           "reference_id",
                                           "dark_id",
                                           "integration_note"};
    // Reflectance and BRDF: the values' standard uncertainties u_<λ> after the values.
    const bool with_u = q != Quantity::kRadiance;
    ASSERT_EQ(rows[0].size(), want.size() + (with_u ? 202 : 101));
    for (std::size_t c = 0; c < want.size(); ++c) EXPECT_EQ(rows[0][c], want[c]);
    EXPECT_EQ(rows[0][want.size()], "380");
    EXPECT_EQ(rows[0][want.size() + 1], "384");
    EXPECT_EQ(rows[0][want.size() + 100], "780");
    EXPECT_EQ(rows[0].back(), with_u ? "u_780" : "780");
    if (with_u) {
      EXPECT_EQ(rows[0][want.size() + 101], "u_380");
      EXPECT_NE(comments.find("uncertainty columns: u_<λ>"), std::string::npos);
      // The synthetic session's readings carry no budget: empty u fields.
      EXPECT_EQ(rows[1].size(), rows[0].size());
      EXPECT_EQ(rows[1].back(), "");
    }
  }
}

TEST(ReadingsCsv, RadianceRowsAreEveryReadingAsMeasured) {
  const Session session = SmallSession();
  std::ostringstream out;
  Result<ReadingsCsvReport> report = WriteReadingsCsv(session, Quantity::kRadiance, out);
  ASSERT_TRUE(report.ok());
  const auto rows = CsvRows(out.str());
  ASSERT_EQ(rows.size(), session.readings.size() + 1);
  EXPECT_EQ(report->rows, session.readings.size());
  EXPECT_EQ(rows[1][1], "reference");
  EXPECT_EQ(rows[2][1], "dark");
  EXPECT_EQ(rows[3][1], "sample");
  for (std::size_t i = 0; i < session.readings.size(); ++i) {
    const Reading& r = session.readings[i];
    const auto& row = rows[i + 1];
    EXPECT_EQ(std::stoll(row[0]), r.id);
    EXPECT_EQ(std::stod(row[3]), r.pose.beta);
    EXPECT_EQ(std::stod(row[6]), r.directions.theta_i);
    EXPECT_EQ(row[13], r.reference_id ? std::to_string(*r.reference_id) : "");
    for (std::size_t b = 0; b < 101; ++b) {
      EXPECT_EQ(std::stod(row[16 + b]), r.spectrum.values[b]) << "shortest form reads back";
    }
  }
}

TEST(ReadingsCsv, BrdfRowsEqualTheAnalyticBrdf) {
  const Session session = SmallSession();
  const AnalyticBrdf paint = AnalyticBrdf::PaintLike();
  std::ostringstream out;
  ASSERT_TRUE(WriteReadingsCsv(session, Quantity::kBrdf, out).ok());
  const auto rows = CsvRows(out.str());
  std::size_t samples = 0;
  for (const Reading& r : session.readings) samples += r.kind == ReadingKind::kSample;
  ASSERT_EQ(rows.size(), samples + 1);
  const WavelengthGrid grid = WavelengthGrid::Pr650();
  for (std::size_t i = 1; i < rows.size(); ++i) {
    ASSERT_EQ(rows[i][1], "sample");
    const Directions d{std::stod(rows[i][6]), std::stod(rows[i][7]), std::stod(rows[i][8]),
                       std::stod(rows[i][9])};
    const std::vector<double> truth = paint.EvaluateSpectrum(d, grid);
    for (std::size_t b = 0; b < grid.count; b += 25) {
      EXPECT_NEAR(std::stod(rows[i][16 + b]), truth[b], 1e-12 * truth[b] + 1e-15);
    }
  }
}

TEST(ReadingsCsv, ReadingsWithoutAReferenceAreListedAsLeftOut) {
  Session session = SmallSession(false);
  session.readings[5].reference_id.reset();
  const std::int64_t lost = session.readings[5].id;
  std::ostringstream out;
  Result<ReadingsCsvReport> report = WriteReadingsCsv(session, Quantity::kReflectance, out);
  ASSERT_TRUE(report.ok());
  ASSERT_EQ(report->skipped.size(), 1u);
  EXPECT_EQ(report->skipped[0].reading_id, lost);
  const std::string comments = Joined(CommentLines(out.str()));
  EXPECT_NE(comments.find("left out: reading " + std::to_string(lost) +
                          ": it names no reference reading"),
            std::string::npos)
      << comments;
  EXPECT_EQ(CsvRows(out.str()).size(), session.readings.size() - 1 /*reference*/ - 1 + 1);
}

TEST(ReadingsCsv, EmptySessionIsAnError) {
  Session empty;
  empty.id = 7;
  std::ostringstream out;
  Result<ReadingsCsvReport> r = WriteReadingsCsv(empty, Quantity::kRadiance, out);
  EXPECT_EQ(r.status().code(), StatusCode::kFailedPrecondition);
  EXPECT_NE(r.status().message().find("session 7"), std::string::npos);
  EXPECT_EQ(WriteReadingsCsv(empty, Quantity::kBrdf, out).status().code(),
            StatusCode::kFailedPrecondition);
}

TEST(DeriveSamples, DarkIsSubtractedAndBrdfUsesTheReferenceIncidence) {
  // One sample at θi = 60° referenced to a white read at θi,ref = 30°.
  const WavelengthGrid grid{500, 100, 2};
  Session s;
  Reading ref;
  ref.id = 10;
  ref.kind = ReadingKind::kReference;
  ref.directions = {30, 0, 30, 180};
  ref.spectrum = {grid, {2.0, 4.0}};
  Reading dark;
  dark.id = 11;
  dark.kind = ReadingKind::kDark;
  dark.spectrum = {grid, {0.5, 1.0}};
  Reading sample;
  sample.id = 12;
  sample.directions = {60, 0, 20, 90};
  sample.spectrum = {grid, {1.1, 1.9}};
  sample.reference_id = 10;
  sample.dark_id = 11;
  s.readings = {ref, dark, sample};
  s.white_reflectance = 0.95;

  Result<DerivedSamples> radiance = DeriveSamples(s, Quantity::kRadiance);
  ASSERT_TRUE(radiance.ok());
  EXPECT_DOUBLE_EQ(radiance->samples[0].values[0], 0.6);
  Result<DerivedSamples> r = DeriveSamples(s, Quantity::kReflectance);
  ASSERT_TRUE(r.ok());
  EXPECT_DOUBLE_EQ(r->samples[0].values[0], 0.6 / 1.5);
  EXPECT_DOUBLE_EQ(r->samples[0].values[1], 0.9 / 3.0);
  Result<DerivedSamples> f = DeriveSamples(s, Quantity::kBrdf);
  ASSERT_TRUE(f.ok());
  const double ratio = std::cos(30 * M_PI / 180) / std::cos(60 * M_PI / 180);
  EXPECT_NEAR(f->samples[0].values[0], 0.4 * 0.95 / M_PI * ratio, 1e-15);
  EXPECT_EQ(f->samples[0].iso, (IsoDirection{60, 20, 90}));
}

// A reading whose integration the meter changed says so in its row (integration_note, quoted when
// it holds a comma); the others leave the column empty.
TEST(ReadingsCsv, IntegrationNoteSaysHowTheMeterChangedTheIntegration) {
  Session session = SmallSession(/*with_dark=*/false);
  ASSERT_GE(session.readings.size(), 3u);
  session.readings[1].integration_ms = 250;
  session.readings[1].integration_note =
      "code 19 (overload): integration halved from 500 to 250 ms";
  session.readings[2].integration_note = "code 18 (low light, weak signal): integration doubled";
  std::ostringstream out;
  ASSERT_TRUE(WriteReadingsCsv(session, Quantity::kRadiance, out).ok());
  const std::string text = out.str();
  const auto rows = CsvRows(text);
  ASSERT_EQ(rows[0][15], "integration_note");
  EXPECT_EQ(rows[1][15], "");
  EXPECT_EQ(rows[2][12], "250");
  EXPECT_EQ(rows[2][15], session.readings[1].integration_note);
  EXPECT_NE(text.find(",\"code 18 (low light, weak signal): integration doubled\","),
            std::string::npos);
  EXPECT_NE(Joined(CommentLines(text)).find("integration_note: how the meter changed"),
            std::string::npos);
}

// Readings with a budget write its standard uncertainty per band: the BRDF's as stored, the
// reflectance's without the BRDF's scale terms, scaled by R / f. Readings without one leave the
// fields empty.
TEST(ReadingsCsv, UncertaintyColumnsHoldEachReadingsBudget) {
  Session session = SmallSession(/*with_dark=*/false);
  std::int64_t without = -1;
  for (Reading& r : session.readings) {
    if (r.kind != ReadingKind::kSample) continue;
    if (without < 0) {
      without = r.id;  // the first sample keeps no budget
      continue;
    }
    r.brdf_u.assign(101, 0.002);
    r.brdf_u_of_ratio.assign(101, 0.001);
  }
  std::ostringstream brdf, refl;
  ASSERT_TRUE(WriteReadingsCsv(session, Quantity::kBrdf, brdf).ok());
  ASSERT_TRUE(WriteReadingsCsv(session, Quantity::kReflectance, refl).ok());
  const auto f = CsvRows(brdf.str()), r = CsvRows(refl.str());
  ASSERT_EQ(f.size(), r.size());
  for (std::size_t i = 1; i < f.size(); ++i) {
    const bool has = std::stoll(f[i][0]) != without;
    for (std::size_t b = 0; b < 101; b += 20) {
      if (!has) {
        EXPECT_EQ(f[i][117 + b], "");
        EXPECT_EQ(r[i][117 + b], "");
        continue;
      }
      EXPECT_EQ(std::stod(f[i][117 + b]), 0.002);
      const double ratio = std::stod(r[i][16 + b]) / std::stod(f[i][16 + b]);
      EXPECT_NEAR(std::stod(r[i][117 + b]), 0.001 * ratio, 1e-12 * ratio);
    }
  }
}

}  // namespace
}  // namespace brdf::exports
