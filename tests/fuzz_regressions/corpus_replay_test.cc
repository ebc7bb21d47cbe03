// Replays the checked-in seed corpus of every fuzz target (fuzz/corpus/<target>/) through the
// same harness code libFuzzer runs, with the normal compiler: each seed must pass every invariant
// the harness checks. A harness that finds a broken promise aborts, which fails the test with
// the harness's message on stderr. Seeds cover the documented formats and their error paths, so
// this also keeps the seeds themselves honest (a seed that stops exercising its path shows up
// in the counts below).
#include <gtest/gtest.h>

#include <algorithm>
#include <cstddef>
#include <cstdint>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <string>
#include <vector>

namespace brdf::fuzz {
int FuzzPr650Reply(const std::uint8_t* data, std::size_t size);
int FuzzPr650Framing(const std::uint8_t* data, std::size_t size);
int FuzzStageCodec(const std::uint8_t* data, std::size_t size);
int FuzzStageRtu(const std::uint8_t* data, std::size_t size);
int FuzzPlanJson(const std::uint8_t* data, std::size_t size);
int FuzzConfig(const std::uint8_t* data, std::size_t size);
int FuzzInterpCsv(const std::uint8_t* data, std::size_t size);
int FuzzStageProfile(const std::uint8_t* data, std::size_t size);
int FuzzMaterial(const std::uint8_t* data, std::size_t size);

namespace {

using Harness = int (*)(const std::uint8_t*, std::size_t);

std::vector<std::filesystem::path> Seeds(const std::string& target) {
  const std::filesystem::path dir = std::filesystem::path(BRDF_FUZZ_CORPUS_DIR) / target;
  std::vector<std::filesystem::path> out;
  if (!std::filesystem::is_directory(dir)) return out;
  for (const auto& entry : std::filesystem::directory_iterator(dir)) {
    if (entry.is_regular_file()) out.push_back(entry.path());
  }
  std::sort(out.begin(), out.end());
  return out;
}

// Runs every seed of `target`; returns how many there were.
std::size_t Replay(const std::string& target, Harness harness) {
  const std::vector<std::filesystem::path> seeds = Seeds(target);
  for (const auto& path : seeds) {
    SCOPED_TRACE(path.string());
    std::ifstream in(path, std::ios::binary);
    const std::string bytes((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
    EXPECT_EQ(harness(reinterpret_cast<const std::uint8_t*>(bytes.data()), bytes.size()), 0);
  }
  // The empty input is every harness's first libFuzzer run too.
  EXPECT_EQ(harness(nullptr, 0), 0);
  return seeds.size();
}

TEST(FuzzCorpusReplay, Pr650Reply) {
  EXPECT_GE(Replay("pr650_reply", FuzzPr650Reply), 10u);
}
TEST(FuzzCorpusReplay, Pr650Framing) {
  EXPECT_GE(Replay("pr650_framing", FuzzPr650Framing), 5u);
}
TEST(FuzzCorpusReplay, StageCodec) {
  EXPECT_GE(Replay("stage_codec", FuzzStageCodec), 3u);
}
TEST(FuzzCorpusReplay, StageRtu) {
  EXPECT_GE(Replay("stage_rtu", FuzzStageRtu), 5u);
}
TEST(FuzzCorpusReplay, PlanJson) {
  EXPECT_GE(Replay("plan_json", FuzzPlanJson), 5u);
}
TEST(FuzzCorpusReplay, Config) {
  EXPECT_GE(Replay("config", FuzzConfig), 3u);
}
TEST(FuzzCorpusReplay, StageProfile) {
  EXPECT_GE(Replay("stage_profile", FuzzStageProfile), 6u);
}
TEST(FuzzCorpusReplay, InterpCsv) {
  EXPECT_GE(Replay("interp_csv", FuzzInterpCsv), 3u);
}
TEST(FuzzCorpusReplay, Material) {
  EXPECT_GE(Replay("material", FuzzMaterial), 12u);
}

}  // namespace
}  // namespace brdf::fuzz
