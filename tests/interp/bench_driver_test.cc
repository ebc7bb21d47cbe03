// bench_interp_driver (bench/interp_driver.cc) as bench/compare.py drives it: a quick check, on a
// small data set, that every command answers, that the timed octant pass agrees with the
// reference check on the same queries, and that the grid matches the O(N) reference. Label
// `bench`: it runs no timing target (speed is measured by bench/run.sh, not by tests).
#include <gmock/gmock.h>
#include <gtest/gtest.h>
#include <unistd.h>

#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <random>
#include <sstream>
#include <string>
#include <vector>

namespace {

namespace fs = std::filesystem;
using ::testing::HasSubstr;
using ::testing::Not;

// The value of "key": in a one-line JSON reply (numbers only), or -1 when missing.
double Field(const std::string& reply, const std::string& key) {
  const std::string tag = "\"" + key + "\":";
  const std::size_t at = reply.find(tag);
  if (at == std::string::npos) return -1;
  return std::strtod(reply.c_str() + at + tag.size(), nullptr);
}

TEST(BenchDriverTest, EveryCommandAnswersAndAgreesWithTheReference) {
  const char* build = std::getenv("BRDF_BUILD_DIR");
  ASSERT_NE(build, nullptr) << "BRDF_BUILD_DIR is not set (run through ctest)";
  const fs::path driver = fs::path(build) / "bench" / "bench_interp_driver";
  const fs::path tool = fs::path(build) / "tools" / "brdf-interp" / "brdf-interp";
  ASSERT_TRUE(fs::exists(driver)) << driver << " was not built";
  ASSERT_TRUE(fs::exists(tool)) << tool << " was not built";
  const fs::path dir =
      fs::path(::testing::TempDir()) / ("bench_driver_test_" + std::to_string(::getpid()));
  fs::remove_all(dir);
  fs::create_directories(dir);

  const std::string samples = (dir / "samples.csv").string();
  ASSERT_EQ(std::system((tool.string() + " synth --grid random 3000 --seed 5 -o " + samples +
                         " 2>/dev/null")
                            .c_str()),
            0);
  const std::string queries = (dir / "queries.csv").string();
  {
    std::ofstream q(queries);
    q << "theta_i,theta_o,phi\n";
    std::mt19937_64 rng(17);
    std::uniform_real_distribution<double> theta(-2.0, 92.0), phi(-5.0, 365.0);
    for (int i = 0; i < 600; ++i) q << theta(rng) << "," << theta(rng) << "," << phi(rng) << "\n";
  }
  const std::string commands = (dir / "commands.txt").string();
  std::ofstream(commands) << "samples s " << samples << "\nqueries q " << queries
                          << "\nrun s q octant spectrum\nrun s q octant evaluate\n"
                             "run s q nearest spectrum\nrun s q delaunay spectrum\ncheck s q 2\n"
                             "grid s 2 10 10 20 360 2\ngridcheck s 7 2\nbogus\nquit\n";
  const std::string replies = (dir / "replies.txt").string();
  ASSERT_EQ(std::system((driver.string() + " <" + commands + " >" + replies).c_str()), 0);
  std::vector<std::string> lines;
  {
    std::ifstream in(replies);
    for (std::string line; std::getline(in, line);) lines.push_back(line);
  }
  fs::remove_all(dir);
  ASSERT_EQ(lines.size(), 10u);
  for (std::size_t i = 0; i + 1 < lines.size(); ++i) {
    EXPECT_THAT(lines[i], Not(HasSubstr("error"))) << "reply " << i;
  }
  EXPECT_THAT(lines[9], HasSubstr("unknown command bogus"));

  EXPECT_EQ(Field(lines[0], "n"), 3000);
  EXPECT_GE(Field(lines[0], "delaunay"), 0) << "no Delaunay build time: " << lines[0];
  EXPECT_EQ(Field(lines[1], "n"), 600);
  // Queries reach past the data: some fail, most do not; both APIs and the check agree.
  const double ok = Field(lines[2], "ok");
  EXPECT_GT(ok, 300);
  EXPECT_LT(ok, 600);
  EXPECT_EQ(Field(lines[3], "ok"), ok);
  EXPECT_EQ(Field(lines[4], "ok"), 600);  // nearest always answers
  EXPECT_GT(Field(lines[5], "ok"), 300);
  EXPECT_EQ(Field(lines[6], "mismatches"), 0) << lines[6];
  EXPECT_EQ(Field(lines[6], "ok"), ok);
  EXPECT_EQ(Field(lines[7], "n"), 2000);
  EXPECT_GT(Field(lines[7], "ok"), 1000);
  EXPECT_EQ(Field(lines[8], "checked"), 286);  // rows 0, 7, …, 1995
  EXPECT_EQ(Field(lines[8], "mismatches"), 0) << lines[8];
}

}  // namespace
