// A readings CSV read back (brdf-export fit --readings): the file brdfd writes today, with its
// u_<λ> columns, and an older layout without them (nor integration_note) read alike.
#include "core/export/readings_csv_reader.h"

#include <gtest/gtest.h>

#include <cmath>
#include <sstream>

#include "core/export/readings_csv.h"
#include "core/export/synthetic_session.h"

namespace brdf::exports {
namespace {

TEST(ReadingsCsvReader, ReadsBackWhatTheExportWroteWithItsUncertainties) {
  SyntheticSessionOptions o;
  o.poses.delta_stop_deg = 22.5;
  Result<Session> session = SyntheticSession(AnalyticBrdf::PaintLike(), o);
  ASSERT_TRUE(session.ok());
  session->name = "paint, glossy";
  std::int64_t without = -1;
  for (Reading& r : session->readings) {
    if (r.kind != ReadingKind::kSample) continue;
    if (without < 0) {
      without = r.id;
      continue;
    }
    r.brdf_u.assign(101, 0.0025);
    r.brdf_u_of_ratio.assign(101, 0.001);
  }
  session->readings[3].integration_note = "quality 19 (overload), halved";
  std::ostringstream out;
  ASSERT_TRUE(WriteReadingsCsv(*session, Quantity::kBrdf, out).ok());
  Result<DerivedSamples> derived = DeriveSamples(*session, Quantity::kBrdf);
  ASSERT_TRUE(derived.ok());

  Result<ReadingsCsv> csv = ParseReadingsCsv(out.str(), "test.csv");
  ASSERT_TRUE(csv.ok()) << csv.status().ToString();
  EXPECT_EQ(csv->session_id, session->id);
  EXPECT_EQ(csv->session_name, "paint, glossy");
  EXPECT_EQ(csv->quantity, "brdf");
  EXPECT_EQ(csv->grid, WavelengthGrid::Pr650());
  EXPECT_TRUE(csv->has_u_columns);
  ASSERT_EQ(csv->rows.size(), derived->samples.size());
  for (std::size_t i = 0; i < csv->rows.size(); ++i) {
    const ReadingsCsvRow& row = csv->rows[i];
    const DerivedSample& s = derived->samples[i];
    EXPECT_EQ(row.id, s.reading_id);
    EXPECT_EQ(row.kind, "sample");
    EXPECT_EQ(row.directions.theta_o, s.directions.theta_o);
    EXPECT_EQ(row.values, s.values);  // the shortest form reads back exactly
    if (row.id == without) {
      EXPECT_TRUE(row.u.empty());
    } else {
      EXPECT_EQ(row.u, std::vector<double>(101, 0.0025));
    }
  }
}

TEST(ReadingsCsvReader, ReadsAnOlderLayoutWithoutUncertaintyColumns) {
  const std::string text =
      "# brdfd readings export: session 4\n"
      "# quantity: brdf in sr⁻¹: …\n"
      "id,kind,alpha_deg,beta_deg,gamma_deg,delta_deg,theta_i_deg,phi_i_deg,theta_o_deg,"
      "phi_o_deg,quality_code,flagged,integration_ms,reference_id,dark_id,500,600\r\n"
      "7,sample,0,10,0,30,10,0,20,180,0,0,0,5,,0.1,0.2\r\n"
      "\n"
      "8,sample,0,20,0,30,20,0,10,180,0,0,0,5,6,0.3,nan\n";
  Result<ReadingsCsv> csv = ParseReadingsCsv(text, "old.csv");
  ASSERT_TRUE(csv.ok()) << csv.status().ToString();
  EXPECT_EQ(csv->session_id, 4);
  EXPECT_FALSE(csv->has_u_columns);
  EXPECT_EQ(csv->grid, (WavelengthGrid{500, 100, 2}));
  ASSERT_EQ(csv->rows.size(), 2u);
  EXPECT_EQ(csv->rows[0].values, (std::vector<double>{0.1, 0.2}));
  EXPECT_TRUE(csv->rows[0].u.empty());
  EXPECT_TRUE(std::isnan(csv->rows[1].values[1]));
}

TEST(ReadingsCsvReader, BadFilesAreRefusedNamingTheLine) {
  const std::string head = "id,theta_i_deg,phi_i_deg,theta_o_deg,phi_o_deg,500,600\n";
  Result<ReadingsCsv> r = ParseReadingsCsv(head + "1,10,0,20,180,0.1\n", "a.csv");
  EXPECT_EQ(r.status().code(), StatusCode::kInvalidArgument);
  EXPECT_NE(r.status().message().find("a.csv, line 2"), std::string::npos);
  r = ParseReadingsCsv(head + "1,10,0,twenty,180,0.1,0.2\n", "a.csv");
  EXPECT_NE(r.status().message().find("theta_o_deg 'twenty'"), std::string::npos);
  r = ParseReadingsCsv("id,theta_i_deg,500\n", "b.csv");
  EXPECT_NE(r.status().message().find("phi_i_deg"), std::string::npos);
  r = ParseReadingsCsv("id,theta_i_deg,phi_i_deg,theta_o_deg,phi_o_deg,500,600,700.5\n", "c.csv");
  EXPECT_NE(r.status().message().find("evenly spaced"), std::string::npos);
  r = ParseReadingsCsv(head.substr(0, head.size() - 1) + ",u_500,u_650\n", "d.csv");
  EXPECT_NE(r.status().message().find("do not match"), std::string::npos);
  EXPECT_EQ(ParseReadingsCsv("# only comments\n", "e.csv").status().code(),
            StatusCode::kInvalidArgument);
}

}  // namespace
}  // namespace brdf::exports
