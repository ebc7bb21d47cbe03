// brdf-stage-probe against brdf-sim's AZ-like drives over real Modbus TCP: a drive set as the
// profile says passes, a drive set to the other word order is reported with what to set (and
// passes once the profile says so), and the executable exits 0 / 1 / 2 with the report.
#include "tools/brdf-stage-probe/stage_probe.h"

#include <gmock/gmock.h>
#include <gtest/gtest.h>
#include <sys/wait.h>

#include <array>
#include <cstdio>
#include <memory>
#include <string>

#include "drivers/stage/profile_file.h"
#include "tools/brdf-sim/stage/simulator.h"

namespace brdf::tools::stage_probe {
namespace {

using drivers::stage::RegisterProfile;
using drivers::stage::WordOrder;
using ::testing::AllOf;
using ::testing::HasSubstr;

class StageProbe : public ::testing::Test {
 protected:
  void StartSim(sim::SimWordOrder order, double alpha_deg = 0, bool rtu = false) {
    sim::StageSimConfig c;
    c.serve_rtu = rtu;
    for (auto& axis : c.axes) axis.word_order = order;
    c.axes[0].initial_deg = alpha_deg;
    sim_ = std::make_unique<sim::StageSimulator>(c, control_);
    std::string error;
    ASSERT_TRUE(sim_->Start(&error)) << error;
  }
  void TearDown() override {
    if (sim_) sim_->Shutdown();
  }

  ProbeOptions Options(RegisterProfile profile) const {
    ProbeOptions o;
    o.bus.endpoint = drivers::stage::TcpEndpoint{"127.0.0.1", sim_->tcp_port()};
    o.bus.response_timeout = std::chrono::milliseconds(200);
    o.bus.reconnect_backoff = std::chrono::milliseconds(10);
    o.profile = std::move(profile);
    o.profile_label = "test";
    o.unit_ids = {1, 2};
    return o;
  }

  ProbeReport Probe(const ProbeOptions& o) {
    auto report = ProbeStage(o, CallContext::WithTimeout(std::chrono::seconds(10)));
    EXPECT_TRUE(report.ok()) << report.status().message();
    return report.ok() ? *report : ProbeReport{};
  }

  sim::SimControl control_;
  std::unique_ptr<sim::StageSimulator> sim_;
};

RegisterProfile AzLowFirst() {
  std::string text(drivers::stage::BuiltinProfileText("az"));
  const std::string from = "word_order = \"high_first\"";
  text.replace(text.find(from), from.size(), "word_order = \"low_first\"");
  auto p = drivers::stage::ParseProfileText(text, "az-low-first.toml");
  EXPECT_TRUE(p.ok()) << p.status().message();
  return *p;
}

TEST_F(StageProbe, ADriveSetAsTheProfileSaysPasses) {
  StartSim(sim::SimWordOrder::kHighFirst, 45);
  const ProbeOptions o = Options(RegisterProfile::AzDefault());
  const ProbeReport r = Probe(o);
  ASSERT_EQ(r.axes.size(), 2u);
  EXPECT_TRUE(r.ok()) << FormatReport(r, o);
  EXPECT_EQ(r.axes[0].word_order, WordOrderVerdict::kMatches);
  EXPECT_EQ(r.axes[0].position_counts, 1250);  // 45° at 10,000 counts/rev
  EXPECT_TRUE(r.axes[0].flags.ready);
  EXPECT_THAT(FormatReport(r, o), HasSubstr("OK: every unit answered"));
}

TEST_F(StageProbe, ADriveSetToLowerWordFirstIsReportedWithWhatToSet) {
  StartSim(sim::SimWordOrder::kLowFirst, 45);
  const ProbeOptions o = Options(RegisterProfile::AzDefault());
  const ProbeReport r = Probe(o);
  ASSERT_EQ(r.axes.size(), 2u);
  EXPECT_FALSE(r.ok());
  for (const AxisProbe& a : r.axes) {
    EXPECT_TRUE(a.answered) << a.error;
    EXPECT_EQ(a.word_order, WordOrderVerdict::kSwapped);
    ASSERT_EQ(a.findings.size(), 1u);
    EXPECT_THAT(a.findings[0],
                AllOf(HasSubstr("lower word first"), HasSubstr("high_first"),
                      HasSubstr("word-order parameter"), HasSubstr("word_order = \"low_first\"")));
  }
  // Read the drive's way round, the report shows the real position and status.
  EXPECT_EQ(r.axes[0].position_counts, 1250);
  EXPECT_TRUE(r.axes[0].flags.ready);
  EXPECT_THAT(FormatReport(r, o), AllOf(HasSubstr("SWAPPED"), HasSubstr("NOT OK")));

  // The same drive with a profile that says low_first passes.
  const ProbeReport fixed = Probe(Options(AzLowFirst()));
  EXPECT_TRUE(fixed.ok());
  EXPECT_EQ(fixed.axes[1].word_order, WordOrderVerdict::kMatches);
}

TEST_F(StageProbe, AProfileThatDoesNotFitTheDriveIsNamedPerUnit) {
  StartSim(sim::SimWordOrder::kHighFirst);
  const ProbeReport r = Probe(Options(RegisterProfile::Moons()));
  ASSERT_EQ(r.axes.size(), 2u);
  EXPECT_FALSE(r.ok());
  EXPECT_FALSE(r.axes[0].answered);
  EXPECT_THAT(r.axes[0].error, AllOf(HasSubstr("status word 0x0001"), HasSubstr("exception 2")));
}

TEST_F(StageProbe, ProbesOverRtuToo) {
  StartSim(sim::SimWordOrder::kLowFirst, -30, /*rtu=*/true);
  ProbeOptions o = Options(RegisterProfile::AzDefault());
  o.bus.endpoint = drivers::stage::RtuEndpoint{sim_->rtu_path(), 115200, 'E', 8, 1};
  o.bus.rtu_drain = std::chrono::milliseconds(100);
  o.unit_ids = {1};
  const ProbeReport r = Probe(o);
  ASSERT_EQ(r.axes.size(), 1u);
  EXPECT_THAT(r.bus, HasSubstr("RTU"));
  EXPECT_TRUE(r.axes[0].answered) << r.axes[0].error;
  EXPECT_EQ(r.axes[0].word_order, WordOrderVerdict::kSwapped);
  EXPECT_EQ(r.axes[0].position_counts, -833);  // −30° at 10,000 counts/rev, rounded
}

TEST(JudgeWordOrder, NeedsEvidence) {
  const RegisterProfile az = RegisterProfile::AzDefault();
  const std::array<std::uint16_t, 2> zero{0, 0};
  EXPECT_EQ(JudgeWordOrder(zero, zero, az), WordOrderVerdict::kUndecided);
  // READY | IN-POS read high word first, position 0: matches; swapped: swapped.
  const std::array<std::uint16_t, 2> status{0x0000, 0x4020};
  const std::array<std::uint16_t, 2> swapped{0x4020, 0x0000};
  EXPECT_EQ(JudgeWordOrder(status, zero, az), WordOrderVerdict::kMatches);
  EXPECT_EQ(JudgeWordOrder(swapped, zero, az), WordOrderVerdict::kSwapped);
  // No status bit set (e.g. a drive with its outputs reassigned), position 1000 laid out lower
  // word first: 1000 × 65536 is far beyond any travel.
  const std::array<std::uint16_t, 2> position_low_first{1000, 0};
  EXPECT_EQ(JudgeWordOrder(zero, position_low_first, az), WordOrderVerdict::kSwapped);
  // A one-register drive gives no evidence.
  const RegisterProfile leadshine = RegisterProfile::Leadshine();
  const std::array<std::uint16_t, 1> one{0x0002};
  EXPECT_EQ(JudgeWordOrder(one, zero, leadshine), WordOrderVerdict::kUndecided);
}

// The executable: exit 0 / 1 with the report on stdout, 2 with the profile file's error.
struct ProbeRun {
  int status = -1;
  std::string output;
};
ProbeRun RunProbe(const std::string& args) {
  const std::string cmd = std::string(BRDF_TEST_BUILD_DIR) +
                          "/tools/brdf-stage-probe/brdf-stage-probe " + args + " 2>&1";
  ProbeRun r;
  FILE* f = popen(cmd.c_str(), "r");
  if (f == nullptr) return r;
  std::array<char, 4096> buf{};
  while (std::fgets(buf.data(), buf.size(), f) != nullptr) r.output += buf.data();
  const int raw = pclose(f);
  r.status = WIFEXITED(raw) ? WEXITSTATUS(raw) : -1;
  return r;
}

TEST_F(StageProbe, TheExecutableReportsAndExitsByTheOutcome) {
  StartSim(sim::SimWordOrder::kLowFirst);
  const std::string bus = "--tcp 127.0.0.1:" + std::to_string(sim_->tcp_port());
  const ProbeRun swapped = RunProbe(bus + " --profile az --unit 1");
  EXPECT_EQ(swapped.status, 1) << swapped.output;
  EXPECT_THAT(swapped.output, AllOf(HasSubstr("unit 1:"), HasSubstr("SWAPPED"),
                                    HasSubstr("word_order = \"low_first\"")));

  const std::string path = ::testing::TempDir() + "/probe-low-first.toml";
  {
    std::string text(drivers::stage::BuiltinProfileText("az"));
    const std::string from = "word_order = \"high_first\"";
    text.replace(text.find(from), from.size(), "word_order = \"low_first\"");
    std::FILE* f = std::fopen(path.c_str(), "w");
    ASSERT_NE(f, nullptr);
    std::fputs(text.c_str(), f);
    std::fclose(f);
  }
  const ProbeRun fits = RunProbe(bus + " --profile-file " + path + " --unit 1 --unit 2");
  EXPECT_EQ(fits.status, 0) << fits.output;
  EXPECT_THAT(fits.output, HasSubstr("OK: every unit answered"));

  const ProbeRun bad = RunProbe(bus + " --profile-file /nonexistent/lab.toml");
  EXPECT_EQ(bad.status, 2) << bad.output;
  EXPECT_THAT(bad.output, HasSubstr("/nonexistent/lab.toml"));
  std::remove(path.c_str());
}

}  // namespace
}  // namespace brdf::tools::stage_probe
