// What the operator sees is true (issue 20, item 4), with brdfctl, brdfd and brdf-sim as real
// processes: `brdfctl watch` shows the pause and its reason while a prompt question is open, and
// withdraws the question (the answer typed afterwards neither answers the prompt nor runs the
// --on-prompt hook); a session started while another holds the rig says which one and that it
// starts by itself, and shows no ETA; refusals use the operator's words and no server paths.
#include <fcntl.h>
#include <google/protobuf/util/json_util.h>
#include <gtest/gtest.h>
#include <sys/stat.h>
#include <unistd.h>

#include <chrono>
#include <filesystem>
#include <fstream>
#include <functional>
#include <sstream>
#include <thread>

#include "brdf/v1/brdf.pb.h"
#include "tests/brdfctl/ctl_test_rig.h"
#include "tests/support/plan_fixtures.h"
#include "tests/support/sim/rig.h"

namespace brdf::testing {
namespace {

using namespace std::chrono_literals;

std::string Describe(const CommandResult& r) {
  return "exit " + std::to_string(r.exit_code) + "\n--- stdout:\n" + r.out + "\n--- stderr:\n" +
         r.err;
}

std::string ReadText(const std::string& path) {
  std::ifstream in(path);
  std::stringstream text;
  text << in.rdbuf();
  return text.str();
}

// Polls until `pred` holds (true) or `timeout` passes (false).
bool Eventually(const std::function<bool()>& pred, std::chrono::milliseconds timeout = 20s) {
  const auto end = std::chrono::steady_clock::now() + timeout;
  while (std::chrono::steady_clock::now() < end) {
    if (pred()) return true;
    std::this_thread::sleep_for(50ms);
  }
  return pred();
}

class OperatorViewTest : public ::testing::Test {
 protected:
  void SetUp() override {
    const Status started = rig_.Start();
    ASSERT_TRUE(started.ok()) << started.ToString();
  }
  void TearDown() override {
    if (HasFailure()) std::cerr << "---- brdfd log ----\n" << rig_.log() << "\n";
  }
  CommandResult Ctl(const std::vector<std::string>& args) {
    Result<CommandResult> r = rig_.Ctl(args);
    EXPECT_TRUE(r.ok()) << r.status().ToString();
    return r.ok() ? *r : CommandResult{-1, "", r.status().ToString()};
  }
  std::string SubmitDemo() {
    const CommandResult r =
        Ctl({"submit", SourceDir() + "/examples/plans/demo.json", "--start", "--quiet"});
    EXPECT_EQ(r.exit_code, 0) << Describe(r);
    return Lines(r.out).empty() ? "" : Lines(r.out)[0];
  }
  CtlRig rig_;
};

TEST_F(OperatorViewTest, WatchWithdrawsTheQuestionWhenTheSessionPausesAndShowsWhy) {
  const std::string id = SubmitDemo();
  ASSERT_FALSE(id.empty());
  // The demo's first step asks for the white standard: brdfctl asks y/N on its standard input (a
  // FIFO the test writes), its output goes to a file.
  const std::string fifo = rig_.dir().file("answers").string();
  const std::string out = rig_.dir().file("watch.out").string();
  const std::string marker = rig_.dir().file("hook-ran").string();
  ASSERT_EQ(::mkfifo(fifo.c_str(), 0600), 0);
  const std::string ctl = *BrdfctlBinary();
  LaunchOptions watch({"-c", "exec '" + ctl + "' watch " + id + " --ask --no-progress " +
                                 "--on-prompt 'touch " + marker + "' < " + fifo + " > " + out +
                                 " 2>&1"});
  watch.set_env = rig_.Env();
  Result<std::unique_ptr<ChildProcess>> watcher = ChildProcess::Launch("sh", "/bin/sh", watch);
  ASSERT_TRUE(watcher.ok()) << watcher.status().ToString();
  const int answers = ::open(fifo.c_str(), O_WRONLY);  // the shell opens the other end
  ASSERT_GE(answers, 0);

  ASSERT_TRUE(Eventually([&] { return ReadText(out).find("[y/N]") != std::string::npos; }))
      << ReadText(out);
  // The operator pauses the session from elsewhere while the question is open.
  const CommandResult paused = Ctl({"pause", id, "--immediate"});
  ASSERT_EQ(paused.exit_code, 0) << Describe(paused);
  ASSERT_TRUE(Eventually([&] { return ReadText(out).find("withdrawn") != std::string::npos; }))
      << ReadText(out);
  const std::string shown = ReadText(out);
  EXPECT_NE(shown.find("withdrawn: the session is now paused"), std::string::npos) << shown;
  EXPECT_NE(shown.find("state: awaiting_operator → paused ("), std::string::npos) << shown;

  // The answer typed now is to a question no longer asked: no hook, no answer.
  ASSERT_EQ(::write(answers, "y\n", 2), 2);
  std::this_thread::sleep_for(700ms);
  EXPECT_FALSE(std::filesystem::exists(marker)) << ReadText(out);
  const CommandResult got = Ctl({"get", id});
  EXPECT_NE(got.out.find("state        paused"), std::string::npos) << Describe(got);
  EXPECT_NE(got.out.find("why          "), std::string::npos) << Describe(got);

  // A second session started now waits: it says for whom, that it starts by itself, no ETA.
  const CommandResult second =
      Ctl({"submit", SourceDir() + "/examples/plans/demo.json", "--start"});
  ASSERT_EQ(second.exit_code, 0) << Describe(second);
  EXPECT_NE(second.out.find(": queued"), std::string::npos) << Describe(second);
  EXPECT_NE(second.out.find("waiting for the rig (session " + id + " holds it, paused"),
            std::string::npos)
      << Describe(second);
  EXPECT_NE(second.out.find("it starts by itself when the rig is free"), std::string::npos)
      << Describe(second);
  const CommandResult list = Ctl({"list", "--state", "queued"});
  ASSERT_EQ(list.exit_code, 0) << Describe(list);
  ASSERT_EQ(Lines(list.out).size(), 1u) << Describe(list);
  EXPECT_EQ(list.out.find("ETA"), std::string::npos) << Describe(list);

  // Refusals in the operator's words: no internal verb names, no server paths.
  const CommandResult abort = Ctl({"abort", id, "--reason", "test over"});
  ASSERT_EQ(abort.exit_code, 0) << Describe(abort);
  const CommandResult again = Ctl({"pause", id});
  EXPECT_NE(again.exit_code, 0) << Describe(again);
  EXPECT_NE(again.err.find("cannot pause a session that is aborted"), std::string::npos)
      << Describe(again);
  EXPECT_EQ(again.err.find("pause_deferred"), std::string::npos) << Describe(again);
  const CommandResult missing = Ctl({"get", "987654"});
  EXPECT_EQ(missing.exit_code, 1) << Describe(missing);
  EXPECT_EQ(missing.err.find(rig_.dir().path().string()), std::string::npos) << Describe(missing);
  EXPECT_EQ(missing.err.find(".db"), std::string::npos) << Describe(missing);

  // The watch follows the abort to its end.
  ::close(answers);
  EXPECT_EQ((*watcher)->WaitUntil(std::chrono::steady_clock::now() + 20s), 4) << ReadText(out);
  EXPECT_NE(ReadText(out).find("ended aborted: aborted by ctl-operator (operator): test over"),
            std::string::npos)
      << ReadText(out);
  EXPECT_FALSE(std::filesystem::exists(marker));
}

// `watch --on-prompt` without --auto-confirm, its standard input not a terminal: watch neither asks
// nor confirms, so the hook is not run; it says so and how to have it run, instead of leaving the
// operator to wonder why the prompt stays open.
TEST_F(OperatorViewTest, WatchSaysTheHookNeedsAutoConfirmWhenItCannotAsk) {
  const std::string id = SubmitDemo();
  ASSERT_FALSE(id.empty());
  const std::string out = rig_.dir().file("watch.out").string();
  const std::string marker = rig_.dir().file("hook-ran").string();
  const std::string ctl = *BrdfctlBinary();
  LaunchOptions watch({"-c", "exec '" + ctl + "' watch " + id +
                                 " --no-progress --on-prompt 'touch " + marker +
                                 "' < /dev/null > " + out + " 2>&1"});
  watch.set_env = rig_.Env();
  Result<std::unique_ptr<ChildProcess>> watcher = ChildProcess::Launch("sh", "/bin/sh", watch);
  ASSERT_TRUE(watcher.ok()) << watcher.status().ToString();

  ASSERT_TRUE(Eventually([&] { return ReadText(out).find("not confirmed") != std::string::npos; }))
      << ReadText(out);
  const std::string shown = ReadText(out);
  EXPECT_NE(shown.find("--on-prompt runs only before a confirmation: add --auto-confirm"),
            std::string::npos)
      << shown;
  EXPECT_FALSE(std::filesystem::exists(marker)) << shown;
  const CommandResult got = Ctl({"get", id});
  EXPECT_NE(got.out.find("state        awaiting_operator"), std::string::npos) << Describe(got);

  const CommandResult abort = Ctl({"abort", id, "--reason", "test over"});
  ASSERT_EQ(abort.exit_code, 0) << Describe(abort);
  EXPECT_EQ((*watcher)->WaitUntil(std::chrono::steady_clock::now() + 20s), 4) << ReadText(out);
}

// A reading whose integration time the meter changed (an overload halves it and measures again)
// says so in `watch`, in `readings` and in the readings CSV, with the time it did use.
TEST_F(OperatorViewTest, AReadingWhoseIntegrationTheMeterHalvedSaysSo) {
  // 100 ms fixed; the next measurement overloads (quality 19) once.
  const std::string plan = rig_.dir().file("tiny.json").string();
  std::ofstream(plan) << plans::TinyPoseList().Json();
  sim::SerialFaults faults;
  faults.quality_code = 19;
  faults.quality_count = 1;
  ASSERT_TRUE(rig_.sim_control().SetSerialFaults(faults).ok());
  const CommandResult submitted = Ctl({"submit", plan, "--start", "--quiet"});
  ASSERT_EQ(submitted.exit_code, 0) << Describe(submitted);
  ASSERT_EQ(Lines(submitted.out).size(), 1u) << Describe(submitted);
  const std::string id = Lines(submitted.out)[0];
  Result<CommandResult> watched =
      rig_.Ctl({"watch", id, "--auto-confirm", "--no-progress", "--on-prompt",
                "'" + *BrdfctlBinary() + "' sim-mount from-prompt --modbus " + rig_.modbus()},
               kCtlOperatorToken, 60s);
  ASSERT_TRUE(watched.ok()) << watched.status().ToString();
  ASSERT_EQ(watched->exit_code, 0) << Describe(*watched);
  const std::string halved = "integration halved from 100 to 50 ms";
  EXPECT_NE(watched->out.find("integration changed by the meter: quality 19 ("), std::string::npos)
      << Describe(*watched);
  EXPECT_NE(watched->out.find(halved), std::string::npos) << Describe(*watched);
  // Only the one reading says so.
  EXPECT_EQ(watched->out.find(halved), watched->out.rfind(halved)) << Describe(*watched);

  const CommandResult readings = Ctl({"readings", id});
  ASSERT_EQ(readings.exit_code, 0) << Describe(readings);
  int changed = 0;
  for (const std::string& line : Lines(readings.out)) {
    if (line.find(halved) == std::string::npos) continue;
    ++changed;
    EXPECT_NE(line.find("50 ms (changed by the meter: quality 19 ("), std::string::npos) << line;
  }
  EXPECT_EQ(changed, 1) << Describe(readings);

  const CommandResult csv =
      Ctl({"export", id, "csv", "--quantity", "radiance", "-o", "-", "--no-progress"});
  ASSERT_EQ(csv.exit_code, 0) << Describe(csv);
  int rows_changed = 0;
  for (const std::string& line : Lines(csv.out)) {
    if (line.empty() || line[0] == '#' || line.find(halved) == std::string::npos) continue;
    ++rows_changed;
    EXPECT_NE(line.find(",50,"), std::string::npos) << "integration_ms 50: " << line;
  }
  EXPECT_EQ(rows_changed, 1) << csv.out.substr(0, 3000);
}

// brdfd knows the simulator's time scale ([rig] time_scale, as quickstart.sh writes it), so the
// first ETA brdfctl shows is the simulated rig's: the plan's estimate at that scale, not a real
// rig's (issue 40: 10:45 falling to 1:02 for a 45 s demo).
TEST_F(OperatorViewTest, TheFirstEtaIsTheSimulatedRigs) {
  const std::string plan = rig_.dir().file("tiny.json").string();
  std::ofstream(plan) << plans::TinyPoseList().Json();
  auto summary = [&](double time_scale) {
    const CommandResult r =
        Ctl({"--json", "validate", plan, "--time-scale", std::to_string(time_scale)});
    EXPECT_EQ(r.exit_code, 0) << Describe(r);
    v1::ValidatePlanResponse reply;
    EXPECT_TRUE(google::protobuf::util::JsonStringToMessage(Lines(r.out).at(0), &reply).ok())
        << r.out;
    return reply.summary();
  };
  const v1::PlanSummary simulated = summary(kSimTimeScale), real = summary(1);
  const CommandResult submitted = Ctl({"submit", plan, "--start", "--quiet"});
  ASSERT_EQ(submitted.exit_code, 0) << Describe(submitted);
  const std::string id = Lines(submitted.out).at(0);
  v1::Session session;
  ASSERT_TRUE(Eventually([&] {
    const CommandResult got = Ctl({"--json", "get", id});
    return got.exit_code == 0 && !Lines(got.out).empty() &&
           google::protobuf::util::JsonStringToMessage(Lines(got.out)[0], &session).ok() &&
           session.state() == v1::SESSION_STATE_AWAITING_OPERATOR;
  })) << session.DebugString();
  // Waiting at its first prompt: every step but the first move is left.
  EXPECT_LE(session.eta_s(), simulated.estimated_duration_s() + 1e-9);
  EXPECT_GT(session.eta_s(), 0.9 * simulated.estimated_duration_s());
  // A real rig's would be longer by most of the devices' time.
  EXPECT_LT(session.eta_s(), real.estimated_duration_s() - 0.5 * real.physical_lower_bound_s())
      << "simulated " << simulated.estimated_duration_s() << " s, real "
      << real.estimated_duration_s() << " s";
  const CommandResult shown = Ctl({"get", id});
  EXPECT_NE(shown.out.find("ETA"), std::string::npos) << Describe(shown);
  EXPECT_EQ(Ctl({"abort", id, "--reason", "test over"}).exit_code, 0);
}

}  // namespace
}  // namespace brdf::testing
