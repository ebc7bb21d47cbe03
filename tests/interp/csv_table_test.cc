// The CSV parser of brdf-interp (core/interp/csv_table.h): what it accepts, and that every error
// names the file, the line and the column.
#include "core/interp/csv_table.h"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

namespace brdf::interp {
namespace {

using ::testing::AllOf;
using ::testing::HasSubstr;

TEST(CsvTableTest, ParsesSamples) {
  const auto r = ParseSamplesCsv(
      "\xEF\xBB\xBFtheta_i, theta_o ,phi,380,\"384\",388nm\r\n"
      "10,20,30,0.1,0.2,0.3\r\n"
      "\n"
      "  11 , 21,+31,1e-3,-2,\"4\"\r\n",
      "s.csv");
  ASSERT_TRUE(r.ok()) << r.status().ToString();
  EXPECT_EQ(r->dims, 3);
  EXPECT_EQ(r->wavelengths_nm, (std::vector<double>{380, 384, 388}));
  EXPECT_EQ(r->wavelength_headers, (std::vector<std::string>{"380", "384", "388nm"}));
  ASSERT_EQ(r->samples->size(), 2u);
  EXPECT_EQ(r->samples->id(1), 1);
  EXPECT_EQ(r->samples->coords(1)[2], 31);
  EXPECT_EQ(r->samples->spectrum(1)[0], 1e-3);
  EXPECT_EQ(r->samples->spectrum(1)[2], 4);
}

TEST(CsvTableTest, ParsesAnisotropicSamplesAndQueries) {
  const auto s = ParseSamplesCsv("theta_i,phi_i,theta_o,phi_o,500\n1,2,3,4,5\n", "s.csv");
  ASSERT_TRUE(s.ok()) << s.status().ToString();
  EXPECT_EQ(s->dims, 4);
  EXPECT_EQ(s->samples->spectrum(0)[0], 5);

  const auto q = ParseQueriesCsv("theta_i,theta_o,phi\n1,2,3\n4,5,6", "q.csv");
  ASSERT_TRUE(q.ok()) << q.status().ToString();
  EXPECT_EQ(q->dims, 3);
  ASSERT_EQ(q->size(), 2u);
  EXPECT_EQ(q->query(1)[2], 6);
  EXPECT_EQ(q->lines[1], 3u);
  const auto none = ParseQueriesCsv("theta_i,phi_i,theta_o,phi_o\n", "q.csv");
  ASSERT_TRUE(none.ok());
  EXPECT_EQ(none->size(), 0u);
  EXPECT_EQ(none->dims, 4);
}

std::string SamplesError(const std::string& text) {
  const auto r = ParseSamplesCsv(text, "samples.csv");
  EXPECT_FALSE(r.ok()) << text;
  if (r.ok()) return "";
  EXPECT_EQ(r.status().code(), StatusCode::kInvalidArgument);
  return r.status().message();
}

TEST(CsvTableTest, ErrorsNameFileLineAndColumn) {
  EXPECT_THAT(SamplesError(""), AllOf(HasSubstr("samples.csv"), HasSubstr("empty")));
  EXPECT_THAT(SamplesError("\n  \n"), HasSubstr("empty"));
  // Missing or misnamed coordinate column.
  EXPECT_THAT(SamplesError("theta_i,phi,380\n1,2,3\n"),
              AllOf(HasSubstr("samples.csv:1:"), HasSubstr("column 2"), HasSubstr("theta_o")));
  EXPECT_THAT(SamplesError("theta_i,theta_o\n1,2\n"),
              AllOf(HasSubstr("samples.csv:1:"), HasSubstr("missing column 3 'phi'")));
  EXPECT_THAT(SamplesError("theta_i,theta_o,phi\n1,2,3\n"), HasSubstr("no wavelength"));
  // Not a number, NaN, infinite, empty, out of range: line and column (with its name).
  EXPECT_THAT(SamplesError("theta_i,theta_o,phi,380\n1,2,3,4\n1,2,abc,4\n"),
              AllOf(HasSubstr("samples.csv:3:"), HasSubstr("column 3 (phi)"),
                    HasSubstr("'abc' is not a number")));
  EXPECT_THAT(SamplesError("theta_i,theta_o,phi,380\n1,2,3,nan\n"),
              AllOf(HasSubstr("samples.csv:2:"), HasSubstr("column 4 (380)"),
                    HasSubstr("not a finite number")));
  EXPECT_THAT(SamplesError("theta_i,theta_o,phi,380\n1,inf,3,4\n"),
              AllOf(HasSubstr("column 2 (theta_o)"), HasSubstr("not a finite")));
  EXPECT_THAT(SamplesError("theta_i,theta_o,phi,380\n1,,3,4\n"),
              AllOf(HasSubstr("samples.csv:2:"), HasSubstr("column 2 (theta_o) is empty")));
  EXPECT_THAT(SamplesError("theta_i,theta_o,phi,380\n1,2,3,1e999\n"),
              HasSubstr("out of the range"));
  EXPECT_THAT(SamplesError("theta_i,theta_o,phi,380\n1,2,3,4x\n"),
              HasSubstr("'4x' is not a number"));
  // Ragged rows (too few, too many, trailing comma).
  EXPECT_THAT(SamplesError("theta_i,theta_o,phi,380,384\n1,2,3,4,5\n1,2,3,4\n"),
              AllOf(HasSubstr("samples.csv:3:"), HasSubstr("4 fields"), HasSubstr("has 5")));
  EXPECT_THAT(SamplesError("theta_i,theta_o,phi,380\n1,2,3,4,5\n"), HasSubstr("5 fields"));
  EXPECT_THAT(SamplesError("theta_i,theta_o,phi,380\n1,2,3,4,\n"), HasSubstr("5 fields"));
  // Header problems.
  EXPECT_THAT(SamplesError("theta_i,theta_o,phi,380,red\n1,2,3,4,5\n"),
              AllOf(HasSubstr("column 5"), HasSubstr("'red'"), HasSubstr("wavelength")));
  EXPECT_THAT(SamplesError("theta_i,theta_o,phi,384,380\n1,2,3,4,5\n"), HasSubstr("increasing"));
  EXPECT_THAT(SamplesError("theta_i,theta_o,phi,380,380\n1,2,3,4,5\n"), HasSubstr("repeats"));
  EXPECT_THAT(SamplesError("theta_i,,phi,380\n1,2,3,4\n"), HasSubstr("no name"));
  EXPECT_THAT(SamplesError("theta_i,theta_o,phi,380\n"), HasSubstr("no data rows"));
  EXPECT_THAT(SamplesError("theta_i,theta_o,phi,\"380\n1,2,3,4\n"), HasSubstr("not closed"));
  // Blank lines still count: the error is on the file's own line 4.
  EXPECT_THAT(SamplesError("\ntheta_i,theta_o,phi,380\n\n1,2,x,4\n"), HasSubstr("samples.csv:4:"));
}

TEST(CsvTableTest, QueryErrors) {
  auto r = ParseQueriesCsv("theta_i,theta_o,phi,380\n1,2,3,4\n", "q.csv");
  ASSERT_FALSE(r.ok());
  EXPECT_THAT(r.status().message(),
              AllOf(HasSubstr("q.csv:1:"), HasSubstr("unexpected column 4"), HasSubstr("'380'")));
  r = ParseQueriesCsv("x,y,z\n1,2,3\n", "q.csv");
  ASSERT_FALSE(r.ok());
  EXPECT_THAT(r.status().message(), HasSubstr("'x' where 'theta_i' was expected"));
  r = ParseQueriesCsv("theta_i,theta_o,phi\n1,2,-nan\n", "q.csv");
  ASSERT_FALSE(r.ok());
  EXPECT_THAT(r.status().message(), AllOf(HasSubstr("q.csv:2:"), HasSubstr("column 3 (phi)")));
}

TEST(CsvTableTest, NeverCrashesOnGarbage) {
  // Cheap stand-in for a fuzzer: every prefix and some byte flips of a valid file parse or fail
  // cleanly.
  const std::string good = "theta_i,theta_o,phi,380,\"3\"\"84\"\n1,2,3,4,5\n\"6\",7 , 8,9,10\n";
  for (std::size_t n = 0; n <= good.size(); ++n) {
    (void)ParseSamplesCsv(good.substr(0, n), "p.csv");
    (void)ParseQueriesCsv(good.substr(0, n), "p.csv");
  }
  for (std::size_t i = 0; i < good.size(); ++i) {
    for (char c : {'\0', ',', '"', '\n', '\r', 'e', '-', '.'}) {
      std::string bad = good;
      bad[i] = c;
      (void)ParseSamplesCsv(bad, "p.csv");
    }
  }
}

}  // namespace
}  // namespace brdf::interp
