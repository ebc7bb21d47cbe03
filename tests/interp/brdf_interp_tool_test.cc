// brdf-interp as a user runs it: the built executable (BRDF_BUILD_DIR, set by brdf_add_test) on
// files in a scratch directory. Checks the output's shape and properties, determinism across
// thread counts and between the fast and reference octant implementations, and that bad input
// exits with status 2 and a message naming the file, line and column.
#include <gmock/gmock.h>
#include <gtest/gtest.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>
#include <vector>

namespace {

namespace fs = std::filesystem;
using ::testing::AllOf;
using ::testing::HasSubstr;

struct ToolRun {
  int status = -1;
  std::string out;
  std::string err;
};

class BrdfInterpToolTest : public ::testing::Test {
 protected:
  void SetUp() override {
    const char* build = std::getenv("BRDF_BUILD_DIR");
    ASSERT_NE(build, nullptr) << "BRDF_BUILD_DIR is not set (run through ctest)";
    tool_ = fs::path(build) / "tools" / "brdf-interp" / "brdf-interp";
    ASSERT_TRUE(fs::exists(tool_)) << tool_ << " was not built";
    dir_ = fs::path(::testing::TempDir()) /
           ("brdf_interp_tool_test_" + std::to_string(::getpid()) + "_" +
            ::testing::UnitTest::GetInstance()->current_test_info()->name());
    fs::remove_all(dir_);
    fs::create_directories(dir_);
  }
  void TearDown() override { fs::remove_all(dir_); }

  std::string Path(const std::string& name) const { return (dir_ / name).string(); }

  void Write(const std::string& name, const std::string& text) const {
    std::ofstream(Path(name)) << text;
  }

  static std::string Slurp(const std::string& path) {
    std::ifstream in(path);
    std::stringstream s;
    s << in.rdbuf();
    return s.str();
  }

  ToolRun Exec(const std::string& args) const {
    const std::string out = Path("stdout.txt"), err = Path("stderr.txt");
    const std::string command = tool_.string() + " " + args + " >" + out + " 2>" + err;
    const int raw = std::system(command.c_str());
    ToolRun r;
    r.status = WIFEXITED(raw) ? WEXITSTATUS(raw) : -1;
    r.out = Slurp(out);
    r.err = Slurp(err);
    return r;
  }

  fs::path tool_;
  fs::path dir_;
};

std::vector<std::vector<std::string>> ParseCsv(const std::string& text) {
  std::vector<std::vector<std::string>> rows;
  std::stringstream lines(text);
  std::string line;
  while (std::getline(lines, line)) {
    std::vector<std::string> fields;
    std::string field;
    bool quoted = false;
    for (char c : line) {
      if (c == '"') {
        quoted = !quoted;
      } else if (c == ',' && !quoted) {
        fields.push_back(field);
        field.clear();
      } else {
        field += c;
      }
    }
    fields.push_back(field);
    rows.push_back(fields);
  }
  return rows;
}

TEST_F(BrdfInterpToolTest, SynthWritesThePapersGrid) {
  const ToolRun r = Exec("synth --grid paper -o " + Path("paper.csv"));
  ASSERT_EQ(r.status, 0) << r.err;
  const auto rows = ParseCsv(Slurp(Path("paper.csv")));
  ASSERT_EQ(rows.size(), 2154u);  // header + 2,153 distinct points
  ASSERT_EQ(rows[0].size(), 104u);
  EXPECT_EQ(rows[0][0], "theta_i");
  EXPECT_EQ(rows[0][3], "380");
  EXPECT_EQ(rows[0][103], "780");
  for (std::size_t i = 1; i < rows.size(); ++i) {
    ASSERT_EQ(rows[i].size(), 104u);
    EXPECT_LE(std::stod(rows[i][0]), 90.0);
    EXPECT_LE(std::stod(rows[i][2]), 180.0);
    EXPECT_GT(std::stod(rows[i][3]), 0.0);
  }
  // The same seed gives the same random file; another seed another one.
  ASSERT_EQ(Exec("synth --grid random 50 --seed 3 -o " + Path("a.csv")).status, 0);
  ASSERT_EQ(Exec("synth --grid random 50 --seed 3 -o " + Path("b.csv")).status, 0);
  ASSERT_EQ(Exec("synth --grid random 50 --seed 4 -o " + Path("c.csv")).status, 0);
  EXPECT_EQ(Slurp(Path("a.csv")), Slurp(Path("b.csv")));
  EXPECT_NE(Slurp(Path("a.csv")), Slurp(Path("c.csv")));
}

TEST_F(BrdfInterpToolTest, ExplainedOutputIsConsistentAndDeterministic) {
  ASSERT_EQ(Exec("synth --grid paper -o " + Path("paper.csv")).status, 0);
  ASSERT_EQ(Exec("synth --grid random 600 --seed 9 --coordinates-only -o " + Path("q.csv")).status,
            0);
  const std::string common = Path("paper.csv") + " " + Path("q.csv") + " --explain";
  const ToolRun one = Exec(common + " --threads 1 -o " + Path("one.csv"));
  ASSERT_EQ(one.status, 0) << one.err;
  EXPECT_THAT(one.err, HasSubstr("600 queries"));
  ASSERT_EQ(Exec(common + " --threads 2 -o " + Path("two.csv")).status, 0);
  ASSERT_EQ(Exec(common + " --method octant-reference -o " + Path("ref.csv")).status, 0);
  const std::string text = Slurp(Path("one.csv"));
  EXPECT_EQ(text, Slurp(Path("two.csv")));
  EXPECT_EQ(text, Slurp(Path("ref.csv")));

  const auto rows = ParseCsv(text);
  ASSERT_EQ(rows.size(), 601u);
  const auto& header = rows[0];
  ASSERT_EQ(header.size(), 3u + 1u + 101u + 4u + 4u + 1u);
  EXPECT_EQ(header[3], "status");
  EXPECT_EQ(header[105], "v0");
  EXPECT_EQ(header[109], "w0");
  EXPECT_EQ(header.back(), "detail");
  const auto samples = ParseCsv(Slurp(Path("paper.csv")));
  int ok = 0, empty = 0;
  for (std::size_t i = 1; i < rows.size(); ++i) {
    const auto& row = rows[i];
    ASSERT_EQ(row.size(), header.size());
    if (row[3] == "empty_octant") {
      ++empty;
      EXPECT_EQ(row[4], "");
      EXPECT_THAT(row.back(), HasSubstr("octant"));
      continue;
    }
    ASSERT_EQ(row[3], "ok");
    ++ok;
    double sum = 0;
    for (int k = 0; k < 4; ++k) {
      const double w = std::stod(row[109 + static_cast<std::size_t>(k)]);
      EXPECT_GE(w, 0);
      sum += w;
    }
    EXPECT_NEAR(sum, 1.0, 1e-12);
    // Every band lies between the vertex rows' values (rows are 0-based data rows).
    for (std::size_t b = 0; b < 101; b += 10) {
      double lo = INFINITY, hi = -INFINITY;
      for (int k = 0; k < 4; ++k) {
        const auto v = static_cast<std::size_t>(std::stoul(row[105 + static_cast<std::size_t>(k)]));
        ASSERT_LT(v + 1, samples.size());
        const double s = std::stod(samples[v + 1][3 + b]);
        lo = std::min(lo, s);
        hi = std::max(hi, s);
      }
      const double value = std::stod(row[4 + b]);
      EXPECT_GE(value, lo - 1e-12);
      EXPECT_LE(value, hi + 1e-12);
    }
  }
  EXPECT_GT(ok, 100);
  EXPECT_GT(empty, 100);  // random queries reach φ > 180°, outside the rig's data

  const ToolRun nearest =
      Exec(Path("paper.csv") + " " + Path("q.csv") + " --method nearest --explain");
  ASSERT_EQ(nearest.status, 0) << nearest.err;
  const auto nrows = ParseCsv(nearest.out);
  EXPECT_EQ(nrows[0].size(), 3u + 1u + 101u + 1u + 1u + 1u);
  EXPECT_EQ(nrows[1][3], "ok");
}

TEST_F(BrdfInterpToolTest, BadInputExitsWithStatusTwoAndSaysWhere) {
  Write("s.csv", "theta_i,theta_o,phi,380,384\n10,20,30,0.1,0.2\n20,30,40,0.3,abc\n");
  Write("q.csv", "theta_i,theta_o,phi\n15,25,35\n");
  ToolRun r = Exec(Path("s.csv") + " " + Path("q.csv"));
  EXPECT_EQ(r.status, 2);
  EXPECT_THAT(r.err, AllOf(HasSubstr("s.csv:3:"), HasSubstr("column 5 (384)"),
                           HasSubstr("'abc' is not a number")));

  Write("ragged.csv", "theta_i,theta_o,phi,380\n10,20,30\n");
  r = Exec(Path("ragged.csv") + " " + Path("q.csv"));
  EXPECT_EQ(r.status, 2);
  EXPECT_THAT(r.err, AllOf(HasSubstr("ragged.csv:2:"), HasSubstr("3 fields")));

  Write("empty.csv", "");
  r = Exec(Path("empty.csv") + " " + Path("q.csv"));
  EXPECT_EQ(r.status, 2);
  EXPECT_THAT(r.err, AllOf(HasSubstr("empty.csv"), HasSubstr("empty")));

  Write("good.csv", "theta_i,theta_o,phi,380\n10,20,30,0.1\n");
  Write("nanq.csv", "theta_i,theta_o,phi\n1,nan,3\n");
  r = Exec(Path("good.csv") + " " + Path("nanq.csv"));
  EXPECT_EQ(r.status, 2);
  EXPECT_THAT(r.err, AllOf(HasSubstr("nanq.csv:2:"), HasSubstr("column 2 (theta_o)")));

  Write("noq.csv", "theta_i,phi\n1,2\n");
  r = Exec(Path("good.csv") + " " + Path("noq.csv"));
  EXPECT_EQ(r.status, 2);
  EXPECT_THAT(r.err, AllOf(HasSubstr("noq.csv:1:"), HasSubstr("theta_o")));

  r = Exec(Path("missing.csv") + " " + Path("q.csv"));
  EXPECT_EQ(r.status, 2);
  EXPECT_THAT(r.err, HasSubstr("missing.csv"));

  Write("q4.csv", "theta_i,phi_i,theta_o,phi_o\n1,2,3,4\n");
  r = Exec(Path("good.csv") + " " + Path("q4.csv"));
  EXPECT_EQ(r.status, 2);
  EXPECT_THAT(r.err, HasSubstr("coordinate columns"));

  r = Exec(Path("good.csv") + " " + Path("q.csv") + " --scale 1,x,1");
  EXPECT_EQ(r.status, 2);
  EXPECT_THAT(r.err, HasSubstr("--scale"));
  r = Exec(Path("good.csv") + " " + Path("q.csv") + " --scale 1,1");
  EXPECT_EQ(r.status, 2);
  EXPECT_THAT(r.err, HasSubstr("axis_scale"));

  Write("s4.csv", "theta_i,phi_i,theta_o,phi_o,500\n1,2,3,4,0.5\n");
  r = Exec(Path("s4.csv") + " " + Path("q4.csv") + " --mirror-phi");
  EXPECT_EQ(r.status, 2);
  EXPECT_THAT(r.err, HasSubstr("mirror_phi"));

  EXPECT_EQ(Exec("--method kriging " + Path("good.csv") + " " + Path("q.csv")).status, 2);
  EXPECT_EQ(Exec("").status, 2);
  EXPECT_EQ(Exec("--help").status, 0);
}

TEST_F(BrdfInterpToolTest, DemoExplainsOneAnswer) {
  const ToolRun r = Exec("demo");
  ASSERT_EQ(r.status, 0) << r.err;
  EXPECT_THAT(r.out,
              AllOf(HasSubstr("2320 poses"), HasSubstr("2153 distinct"), HasSubstr("Status: ok"),
                    HasSubstr("Vertices:"), HasSubstr("Error against the analytic truth")));
  const ToolRun flag = Exec("--demo --method nearest");
  ASSERT_EQ(flag.status, 0) << flag.err;
  EXPECT_THAT(flag.out, HasSubstr("method nearest"));
  const ToolRun far = Exec("demo --query 5,85,179");
  ASSERT_EQ(far.status, 0) << far.err;
  EXPECT_THAT(far.out, HasSubstr("Status: empty_octant"));
}

TEST_F(BrdfInterpToolTest, HalfDifferenceCoordinates) {
  ASSERT_EQ(Exec("synth --grid paper -o " + Path("paper.csv")).status, 0);
  ASSERT_EQ(Exec("synth --grid random 200 --seed 3 --coordinates-only -o " + Path("q.csv")).status,
            0);
  for (const char* method : {"octant", "delaunay", "nearest"}) {
    const ToolRun r = Exec(Path("paper.csv") + " " + Path("q.csv") + " --method " + method +
                           " --coordinates half-diff --explain -o " + Path("out.csv"));
    ASSERT_EQ(r.status, 0) << method << ": " << r.err;
    const auto rows = ParseCsv(Slurp(Path("out.csv")));
    ASSERT_EQ(rows.size(), 201u) << method;
    std::size_t ok = 0;
    for (std::size_t i = 1; i < rows.size(); ++i) ok += rows[i][3] == "ok";
    EXPECT_GT(ok, 0u) << method;
  }
  // 4D data has no half/difference angles: refused, naming the option.
  ASSERT_EQ(Exec("synth --grid random 50 --dims 4 -o " + Path("s4.csv")).status, 0);
  ASSERT_EQ(Exec("synth --grid random 5 --dims 4 --coordinates-only -o " + Path("q4.csv")).status,
            0);
  const ToolRun four = Exec(Path("s4.csv") + " " + Path("q4.csv") + " --coordinates half-diff");
  EXPECT_EQ(four.status, 2);
  EXPECT_THAT(four.err, HasSubstr("coordinates"));
  const ToolRun demo = Exec("demo --coordinates half-diff --query 42.5,42.5,177.5");
  ASSERT_EQ(demo.status, 0) << demo.err;
  EXPECT_THAT(demo.out, AllOf(HasSubstr("half/difference"), HasSubstr("Status: ok")));
}

TEST_F(BrdfInterpToolTest, AccuracyComparesBothCoordinates) {
  const ToolRun r = Exec("accuracy --sample glossy --queries 2000");
  ASSERT_EQ(r.status, 0) << r.err;
  EXPECT_THAT(r.out,
              AllOf(HasSubstr("glossy"), HasSubstr("| octant | θh, θd, φd |"),
                    HasSubstr("| delaunay | θi, θo, φ |"), HasSubstr("| nearest | θh, θd, φd |")));
  EXPECT_EQ(Exec("accuracy --sample velvet").status, 2);
}

// The lines of `text` that start with `prefix`.
std::vector<std::string> LinesStartingWith(const std::string& text, const std::string& prefix) {
  std::vector<std::string> out;
  std::istringstream in(text);
  for (std::string line; std::getline(in, line);) {
    if (line.rfind(prefix, 0) == 0) out.push_back(line);
  }
  return out;
}

TEST_F(BrdfInterpToolTest, AccuracyLogBlendChangesTheBlendingMethodsOnly) {
  const ToolRun linear = Exec("accuracy --sample glossy --queries 2000");
  const ToolRun log = Exec("accuracy --sample glossy --queries 2000 --blend log");
  ASSERT_EQ(linear.status, 0) << linear.err;
  ASSERT_EQ(log.status, 0) << log.err;
  EXPECT_THAT(linear.out, HasSubstr("; linear blend"));
  EXPECT_THAT(log.out, HasSubstr("; log blend (floor 1e-6 of each band's largest value)"));
  // Nearest neighbour blends nothing: its rows are the same either way.
  const auto nearest_linear = LinesStartingWith(linear.out, "| nearest |");
  ASSERT_EQ(nearest_linear.size(), 2u);
  EXPECT_EQ(LinesStartingWith(log.out, "| nearest |"), nearest_linear);
  // The blending methods answer the same queries (same ok counts) with other values.
  for (const char* method : {"| octant | θh, θd, φd |", "| delaunay | θi, θo, φ |"}) {
    const auto a = LinesStartingWith(linear.out, method);
    const auto b = LinesStartingWith(log.out, method);
    ASSERT_EQ(a.size(), 1u) << method;
    ASSERT_EQ(b.size(), 1u) << method;
    EXPECT_NE(a[0], b[0]) << method;
    const std::string ok_a = a[0].substr(0, a[0].find('|', std::string(method).size()));
    EXPECT_EQ(b[0].substr(0, ok_a.size()), ok_a) << method;
  }
  const ToolRun bad = Exec("accuracy --blend cubic");
  EXPECT_EQ(bad.status, 2);
  EXPECT_THAT(bad.err, HasSubstr("--blend"));
}

}  // namespace
