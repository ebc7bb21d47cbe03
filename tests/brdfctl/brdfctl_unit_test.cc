// brdfctl's pieces that need no daemon: exit codes, the progress line, the ETA calibration, the
// prompt hook's environment and exit handling, plan files, the simulator helper's mapping.
#include <gtest/gtest.h>

#include <algorithm>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <sstream>
#include <string>
#include <vector>

#include "core/geometry.h"
#include "daemon/config/config.h"
#include "tests/support/test_env.h"
#include "tools/brdfctl/commands/sim_mount.h"
#include "tools/brdfctl/exit_codes.h"
#include "tools/brdfctl/output/rounds_text.h"
#include "tools/brdfctl/output/session_text.h"
#include "tools/brdfctl/output/text_format.h"
#include "tools/brdfctl/output/uncertainty_text.h"
#include "tools/brdfctl/plan_file.h"
#include "tools/brdfctl/rpc_error.h"
#include "tools/brdfctl/watch/eta_calibrator.h"
#include "tools/brdfctl/watch/progress_line.h"
#include "tools/brdfctl/watch/prompt_hook.h"

namespace brdf::ctl {
namespace {

TEST(ExitCodes, FollowTheStatusCode) {
  EXPECT_EQ(ExitCodeFor(grpc::StatusCode::OK), kExitOk);
  EXPECT_EQ(ExitCodeFor(grpc::StatusCode::INVALID_ARGUMENT), kExitInvalid);
  EXPECT_EQ(ExitCodeFor(grpc::StatusCode::UNAUTHENTICATED), kExitAuth);
  EXPECT_EQ(ExitCodeFor(grpc::StatusCode::PERMISSION_DENIED), kExitAuth);
  for (grpc::StatusCode c : {grpc::StatusCode::NOT_FOUND, grpc::StatusCode::FAILED_PRECONDITION,
                             grpc::StatusCode::UNAVAILABLE, grpc::StatusCode::INTERNAL,
                             grpc::StatusCode::DEADLINE_EXCEEDED}) {
    EXPECT_EQ(ExitCodeFor(c), kExitFailure) << GrpcCodeName(c);
  }
}

TEST(RpcError, NamesTheCallTheCodeAndTheMessage) {
  const std::string text = DescribeRpcError(
      grpc::Status(grpc::StatusCode::NOT_FOUND, "no session 42"), "GetSession", "host:1");
  EXPECT_NE(text.find("GetSession"), std::string::npos) << text;
  EXPECT_NE(text.find("NOT_FOUND"), std::string::npos) << text;
  EXPECT_NE(text.find("no session 42"), std::string::npos) << text;
  const std::string down = DescribeRpcError(
      grpc::Status(grpc::StatusCode::UNAVAILABLE, "connection refused"), "ListSessions", "h:7");
  EXPECT_NE(down.find("h:7"), std::string::npos) << down;
}

TEST(UncertaintyText, ExpandedUncertaintyOfTheBrdfOrNotEstimated) {
  v1::Reading sample;
  sample.set_kind(v1::READING_KIND_SAMPLE);
  EXPECT_EQ(UncertaintySummary(sample, 2), "± not estimated");
  v1::ReadingUncertainty* u = sample.mutable_uncertainty();
  u->set_quantity(v1::QUANTITY_BRDF);
  for (double v : {0.1, 0.2, 0.0, 0.4}) u->add_value(v);
  for (double c : {0.001, 0.002, 0.5, 0.008}) u->add_combined(c);
  // U / |f| at k = 2: 2 %, 2 %, (f = 0: left out), 4 %: median 2 %, range 2–4 %.
  EXPECT_EQ(UncertaintySummary(sample, 2), "brdf ±2 % (k=2; 2–4 % over bands)");
  EXPECT_EQ(UncertaintySummary(sample, 1), "brdf ±1 % (k=1; 1–2 % over bands)");
  EXPECT_EQ(UncertaintyBand(*u, 1, 2), "brdf 0.2 ± 0.004 sr⁻¹ (k=2)");
  EXPECT_EQ(UncertaintyBand(*u, 7, 2), "");
  v1::Reading dark;
  dark.set_kind(v1::READING_KIND_DARK);
  EXPECT_EQ(UncertaintySummary(dark, 2), "");
}

TEST(TextFormat, ShortNamesAndDurations) {
  EXPECT_EQ(StateName(v1::SESSION_STATE_AWAITING_OPERATOR), "awaiting_operator");
  EXPECT_EQ(PromptKindName(v1::PROMPT_KIND_MOUNT_WHITE), "mount_white");
  v1::SessionState state{};
  EXPECT_TRUE(ParseStateName("paused", &state));
  EXPECT_EQ(state, v1::SESSION_STATE_PAUSED);
  EXPECT_FALSE(ParseStateName("unspecified", &state));
  EXPECT_FALSE(ParseStateName("runing", &state));
  EXPECT_EQ(Duration(42), "42 s");
  EXPECT_EQ(Duration(187), "3:07");
  EXPECT_EQ(Duration(3723), "1:02:03");
  EXPECT_EQ(Duration(-1), "?");
}

TEST(TextFormat, PosesPrintToTheStagesResolutionNotTheFloatingPointNoise) {
  v1::Pose pose;
  pose.set_alpha(2.0255e-15);  // a sample-fixed pose, computed
  pose.set_beta(-29.99999999);
  pose.set_gamma(12.5);
  pose.set_delta(-0.0001);
  EXPECT_EQ(PoseText(pose), "α 0° β -30° γ 12.5° δ 0°");
  EXPECT_EQ(StageAngle(123.4567), "123.457");
  EXPECT_EQ(StageAngle(-30.0014), "-30.001");
  EXPECT_EQ(StageAngle(45), "45");
}

// The display columns of UTF-8 text (α, δ, →, – and ° are one column each).
std::size_t Columns(const std::string& text) {
  return static_cast<std::size_t>(
      std::count_if(text.begin(), text.end(), [](char c) { return (c & 0xC0) != 0x80; }));
}

v1::Adaptive PaperGoal() {
  v1::Adaptive a;
  a.mutable_target()->set_expanded_uncertainty(0.05);
  a.mutable_budget()->set_max_readings(464);
  a.mutable_budget()->set_max_rig_minutes(38);
  a.mutable_budget()->set_max_prompts(60);
  return a;
}

v1::AdaptiveRound RoundOf(int number, double left, std::vector<double> deltas) {
  v1::AdaptiveRound round;
  round.set_round(number);
  for (double delta : deltas) {
    v1::Pose* p = round.add_poses();
    p->set_alpha(12.5);
    p->set_beta(-32.5);
    p->set_delta(delta);
  }
  round.set_predicted_gain(0.01234);
  round.set_uncertainty_left(left);
  round.set_readings_used(188);
  round.set_first_step(422);
  round.set_step_count(96);
  round.set_spent_rig_s(1034);
  round.set_spent_prompts(31);
  round.set_rig_s(242);
  round.set_prompts(6);
  return round;
}

TEST(RoundsText, ARoundAgainstTheTargetAndBudgetsAndWhatItMeasuresNext) {
  const v1::AdaptiveRound round = RoundOf(2, 0.07123, {45, 45, 146.25, 11.25});
  const std::vector<std::string> lines = AdaptiveRoundLines(round, PaperGoal());
  ASSERT_EQ(lines.size(), 5u);
  EXPECT_EQ(lines[0], "round 2 (from 188 of 464 readings): uncertainty left 0.0712, target 0.05");
  EXPECT_EQ(lines[1], "  spent " + Duration(1034) + " of " + Duration(38 * 60) +
                          " rig time, 31 of 60 prompts; predicted gain 0.0123");
  EXPECT_EQ(lines[2],
            "  next: 4 poses, steps 422–517, +" + Duration(242) + " rig time, +6 prompts");
  EXPECT_EQ(lines[3], "  δ 45° → 146.25° → 11.25°");
  // As many poses as fit in 80 columns: two of these.
  EXPECT_EQ(lines[4], "  first poses: α 12.5° β -32.5° γ 0° δ 45°; α 12.5° β -32.5° γ 0° δ 45°");
  for (const std::string& line : lines) EXPECT_LE(Columns(line), 80u) << line;

  // A budget left unset is not named; an expected-error target says so.
  v1::Adaptive readings_only;
  readings_only.mutable_target()->set_expected_error(0.1);
  readings_only.mutable_budget()->set_max_readings(300);
  const std::vector<std::string> plain = AdaptiveRoundLines(round, readings_only);
  EXPECT_EQ(plain[1], "  spent " + Duration(1034) + " rig time, 31 prompts; predicted gain 0.0123");
  EXPECT_EQ(AdaptiveGoalText(readings_only), "target expected error ≤ 0.1; budget 300 readings");
  EXPECT_EQ(AdaptiveGoalText(PaperGoal()), "target U (k = 2) ≤ 0.05; budget 464 readings, " +
                                               Duration(38 * 60) + " rig time, 60 prompts");
}

// The sample-fixed form: a round's poses are where the operator places lamp and detector, shown
// as directions (the prompts' whole degrees), and the table's column is the θi range.
TEST(RoundsText, TheSampleFixedFormShowsDirectionsNotStagePoses) {
  v1::AdaptiveRound round = RoundOf(1, 0.5, {});
  const IsoDirection targets[] = {{50, 5, 130}, {65, 10, 30}, {25, 75, 90}};
  for (const IsoDirection& t : targets) {
    const Result<Pose> pose = InverseKinematics(t);
    ASSERT_TRUE(pose.ok()) << pose.status().ToString();
    v1::Pose* p = round.add_poses();
    p->set_alpha(pose->alpha);
    p->set_beta(pose->beta);
    p->set_delta(pose->delta);
  }
  v1::Adaptive fixed = PaperGoal();
  fixed.mutable_sample_fixed();
  const std::vector<std::string> lines = AdaptiveRoundLines(round, fixed);
  ASSERT_EQ(lines.size(), 4u);
  EXPECT_EQ(lines[3], "  first directions: θi 50° θo 5° φ 130°; θi 65° θo 10° φ 30°");
  for (const std::string& line : lines) EXPECT_LE(Columns(line), 80u) << line;
  EXPECT_EQ(AdaptiveRoundLines(round, PaperGoal()).size(), 5u);  // the rotation form's δ lines

  // The daemon sends each pose's directions (AdaptiveRound.directions): those are shown.
  v1::AdaptiveRound sent = round;
  for (const IsoDirection& t : targets) {
    v1::Directions* d = sent.add_directions();
    d->set_theta_i(t.theta_i + 1);
    d->set_theta_o(t.theta_o);
    d->set_phi_o(t.phi);
  }
  EXPECT_EQ(AdaptiveRoundLines(sent, fixed)[3],
            "  first directions: θi 51° θo 5° φ 130°; θi 66° θo 10° φ 30°");

  std::ostringstream out;
  PrintRoundsTable(out, {round}, fixed);
  EXPECT_NE(out.str().find("poses  θi\n"), std::string::npos) << out.str();
  EXPECT_NE(out.str().find("  3  25°–65°\n"), std::string::npos) << out.str();
}

TEST(RoundsText, TheStopAgainstTheBudgetsWithinEightyColumns) {
  v1::AdaptiveStop stop;
  stop.set_reason("reading budget spent");
  stop.set_uncertainty_left(0.04123);
  stop.set_rounds(3);
  stop.set_readings(212);
  stop.set_rig_s(1890);
  stop.set_prompts(40);
  const std::vector<std::string> lines = AdaptiveStopLines(stop, PaperGoal());
  ASSERT_EQ(lines.size(), 3u);
  EXPECT_EQ(lines[0], "adaptive stop: reading budget spent; uncertainty left 0.0412 (target 0.05)");
  EXPECT_EQ(lines[1], "  after 3 round(s): 212 of 464 readings, " + Duration(1890) + " of " +
                          Duration(38 * 60) + " rig time,");
  EXPECT_EQ(lines[2], "  40 of 60 prompts");
  for (const std::string& line : lines) EXPECT_LE(Columns(line), 80u) << line;
  // Without budgets of rig time and prompts it fits on two.
  v1::Adaptive readings_only = PaperGoal();
  readings_only.mutable_budget()->clear_max_rig_minutes();
  readings_only.mutable_budget()->clear_max_prompts();
  const std::vector<std::string> two = AdaptiveStopLines(stop, readings_only);
  ASSERT_EQ(two.size(), 2u);
  EXPECT_EQ(two[1],
            "  after 3 round(s): 212 of 464 readings, " + Duration(1890) + " rig time, 40 prompts");
}

TEST(RoundsText, LongTextWrapsAtSpacesWithinEightyColumns) {
  const std::string reason =
      "stopped: adaptive: reading budget spent; uncertainty left 0.0412 (target 0.001); 3 "
      "round(s), 33 readings, 1.3 min of rig time, 6 prompts";
  const std::vector<std::string> lines = WrapText(reason);
  ASSERT_EQ(lines.size(), 2u);
  std::string joined;
  for (const std::string& line : lines) {
    EXPECT_LE(Columns(line), 80u) << line;
    joined += joined.empty() ? line : " " + line.substr(2);
  }
  EXPECT_EQ(joined, reason);
  EXPECT_EQ(lines[1].rfind("  3 round(s)", 0), 0u) << lines[1];
  EXPECT_EQ(WrapText("short"), std::vector<std::string>{"short"});
}

TEST(RoundsText, TheTableHasARowAndABarPerRoundWithinEightyColumns) {
  std::vector<v1::AdaptiveRound> rounds;
  const double left[] = {0.739, 0.461, 0.277, 0.027};
  for (int i = 0; i < 4; ++i) rounds.push_back(RoundOf(i + 1, left[i], {11.25, 146.25}));
  std::ostringstream out;
  PrintRoundsTable(out, rounds, PaperGoal());
  std::vector<std::string> lines;
  std::istringstream in(out.str());
  for (std::string line; std::getline(in, line);) lines.push_back(line);
  int rows = 0;
  int bars = 0;
  for (const std::string& line : lines) {
    EXPECT_LE(Columns(line), 80u) << line;
    if (line.find("11.25°–146.25°") != std::string::npos) ++rows;
    if (line.find('#') != std::string::npos) ++bars;
  }
  EXPECT_EQ(rows, 4);
  EXPECT_EQ(bars, 4);
  EXPECT_NE(out.str().find("    1       188  0.739"), std::string::npos) << out.str();
  // The bars fall with the uncertainty; the target's mark is where 0.05 is on the scale (50
  // columns for the highest, 0.739); the last round is below it.
  const auto bar_of = [&](const std::string& value) {
    for (const std::string& line : lines) {
      if (line.find(" " + value + " ") != std::string::npos &&
          line.find('|') != std::string::npos) {
        return line;
      }
    }
    return std::string();
  };
  const std::string first = bar_of("0.739");
  const std::string last = bar_of("0.027");
  EXPECT_EQ(std::count(first.begin(), first.end(), '#'), 49);  // 50 columns, the target's '|'
  EXPECT_EQ(std::count(last.begin(), last.end(), '#'), 2);
  EXPECT_EQ(last.find('|') - last.find('#'), 3u) << last;  // mark at column 3 (0.05 / 0.01478)
  EXPECT_NE(out.str().find("round 4 (from 188 of 464 readings)"), std::string::npos);
  EXPECT_EQ(RoundsSoFarText(rounds),
            "4 round(s) so far; uncertainty left 0.739 → 0.461 → 0.277 → 0.027");
}

TEST(FaultText, SaysWhetherTheSessionPausedOrGoesOnPastASkippedPose) {
  v1::Fault f;
  f.set_step_index(12);
  f.set_code("device_error");
  f.set_device_code(19);
  f.set_attempt(2);
  f.set_reason("quality 19 (light level too high (overload))");
  EXPECT_NE(FaultText(f).find("— session paused"), std::string::npos) << FaultText(f);
  f.set_will_retry(true);
  EXPECT_NE(FaultText(f).find("— will retry"), std::string::npos) << FaultText(f);
  f.set_will_retry(false);
  f.set_reason("step skipped: step 12: the meter overloads at pose α 0°, β 72.8°, δ 157.5°");
  const std::string text = FaultText(f);
  EXPECT_NE(text.find("device_error 19: step skipped: step 12"), std::string::npos) << text;
  EXPECT_EQ(text.substr(text.size() - std::string("— the session goes on").size()),
            "— the session goes on");
}

TEST(ProgressLine, ShowsCountsPercentEtaPoseAndQuality) {
  ProgressView v;
  v.state = "running";
  v.done_steps = 45;
  v.total_steps = 120;
  v.eta_s = 42;
  v1::Pose pose;
  pose.set_alpha(20);
  pose.set_beta(-30);
  pose.set_delta(22.5);
  v.pose = pose;
  v.quality_code = 0;
  const std::string line = RenderProgressLine(v, 120);
  EXPECT_NE(line.find("45/120 37%"), std::string::npos) << line;
  EXPECT_NE(line.find("ETA 42 s"), std::string::npos) << line;
  EXPECT_NE(line.find("δ 22.5°"), std::string::npos) << line;
  EXPECT_NE(line.find("q 0"), std::string::npos) << line;
  EXPECT_LE(DisplayWidth(line), 120u);
  // The bar is filled in proportion.
  const std::size_t open = line.find('['), close = line.find(']');
  ASSERT_NE(open, std::string::npos);
  const std::string bar = line.substr(open + 1, close - open - 1);
  const double filled = static_cast<double>(std::count(bar.begin(), bar.end(), '#'));
  EXPECT_NEAR(filled / static_cast<double>(bar.size()), 45.0 / 120.0, 1.0 / bar.size() + 1e-9);
}

TEST(ProgressLine, NeverWiderThanTheTerminalAndKeepsTheCounts) {
  ProgressView v;
  v.state = "awaiting_operator";
  v.done_steps = 1999;
  v.total_steps = 2320;
  v.eta_s = 36000;
  v.pose = v1::Pose();
  v.quality_code = 18;
  for (int width : {20, 30, 45, 60, 80, 200}) {
    const std::string line = RenderProgressLine(v, width);
    EXPECT_LE(DisplayWidth(line), static_cast<std::size_t>(width)) << width << ": " << line;
    if (width >= 30) {
      EXPECT_NE(line.find("1999/2320"), std::string::npos) << line;
    }
  }
}

TEST(EtaCalibrator, PassesTheDaemonsEtaThroughUntilItHasSeenEnough) {
  EtaCalibrator c;
  c.OnStep(v1::STEP_KIND_MOVE, 100, 0);
  c.OnStep(v1::STEP_KIND_SAMPLE, 90, 1);
  EXPECT_FALSE(c.factor().has_value());
  EXPECT_DOUBLE_EQ(c.Eta(90), 90);
}

TEST(EtaCalibrator, LearnsTheRigsPaceAndIgnoresPrompts) {
  // A rig 10× faster than the model: each step takes 10 model seconds in 1 real second.
  EtaCalibrator c;
  double eta = 500, t = 0;
  c.OnStep(v1::STEP_KIND_MOVE, eta, t);
  for (int i = 0; i < 6; ++i) {
    eta -= 10;
    t += 1;
    c.OnStep(i % 2 ? v1::STEP_KIND_SAMPLE : v1::STEP_KIND_MOVE, eta, t);
  }
  // An operator takes 300 real seconds over a prompt the model costs 30 s: not the rig's pace.
  eta -= 30;
  t += 300;
  c.OnStep(v1::STEP_KIND_PROMPT, eta, t);
  ASSERT_TRUE(c.factor().has_value());
  EXPECT_NEAR(*c.factor(), 0.1, 1e-9);
  EXPECT_NEAR(c.Eta(eta), eta * 0.1, 1e-9);
  // A pause in between is not counted either.
  c.Interrupt();
  c.OnStep(v1::STEP_KIND_SAMPLE, eta - 10, t + 1000);
  EXPECT_NEAR(*c.factor(), 0.1, 1e-9);
}

TEST(PromptHook, SeesThePromptInItsEnvironment) {
  testing::TempDir dir("brdfctl-hook");
  const std::string out = dir.file("env.txt").string();
  v1::Prompt prompt;
  prompt.set_step_index(7);
  prompt.set_kind(v1::PROMPT_KIND_CLOSE_SHUTTER);
  prompt.set_text("Close the lamp shutter");
  prompt.mutable_pose()->set_delta(22.5);
  const Status st = RunPromptHook(
      "printf '%s|%s|%s|%s|%s' \"$BRDF_SESSION_ID\" \"$BRDF_PROMPT_STEP\" \"$BRDF_PROMPT_KIND\" "
      "\"$BRDF_PROMPT_DELTA\" \"$BRDF_PROMPT_TEXT\" > '" +
          out + "'",
      "12", prompt);
  ASSERT_TRUE(st.ok()) << st.ToString();
  std::ifstream in(out);
  std::string text;
  std::getline(in, text);
  EXPECT_EQ(text, "12|7|close_shutter|22.5|Close the lamp shutter");
}

TEST(PromptHook, AFailingCommandLeavesThePromptPendingWithTheAnswerCommand) {
  v1::Prompt prompt;
  prompt.set_step_index(3);
  prompt.set_kind(v1::PROMPT_KIND_MOUNT_WHITE);
  const Status st = RunPromptHook("exit 5", "9", prompt);
  EXPECT_EQ(st.code(), StatusCode::kFailedPrecondition);
  EXPECT_NE(st.message().find("status 5"), std::string::npos) << st.message();
  EXPECT_NE(st.message().find("brdfctl answer 9 3"), std::string::npos) << st.message();
}

TEST(PlanFile, ReadsAPlanAndNamesFileLineAndFieldOnErrors) {
  testing::TempDir dir("brdfctl-plan");
  const std::string good = dir.file("good.json").string();
  std::ofstream(good)
      << R"({"name": "p", "poseList": {"poses": [{"alpha": 0, "beta": 10, "delta": 45}]}})";
  Result<v1::Plan> plan = ReadPlanFile(good);
  ASSERT_TRUE(plan.ok()) << plan.status().ToString();
  EXPECT_EQ(plan->pose_list().poses_size(), 1);

  const std::string bad = dir.file("bad.json").string();
  std::ofstream(bad) << "{\n  \"name\": \"p\",\n  \"measurement\": {\"averages\": \"many\"}\n}\n";
  Result<v1::Plan> broken = ReadPlanFile(bad);
  ASSERT_FALSE(broken.ok());
  EXPECT_EQ(broken.status().code(), StatusCode::kInvalidArgument);
  EXPECT_NE(broken.status().message().find(bad), std::string::npos) << broken.status().message();
  EXPECT_NE(broken.status().message().find("measurement.averages"), std::string::npos)
      << broken.status().message();
  EXPECT_NE(broken.status().message().find("line 3"), std::string::npos)
      << broken.status().message();

  EXPECT_EQ(ReadPlanFile(dir.file("missing.json").string()).status().code(), StatusCode::kNotFound);
}

TEST(SimMount, MapsTargetsAndPromptKinds) {
  EXPECT_EQ(MountedTargetValue("sample"), 0);
  EXPECT_EQ(MountedTargetValue("white"), 1);
  EXPECT_EQ(MountedTargetValue("dark"), 2);
  EXPECT_FALSE(MountedTargetValue("grey").has_value());
  EXPECT_EQ(TargetForPromptKind("mount_white"), "white");
  EXPECT_EQ(TargetForPromptKind("mount_sample"), "sample");
  EXPECT_EQ(TargetForPromptKind("close_shutter"), "dark");
  EXPECT_EQ(TargetForPromptKind("relocate_detector"), "");
  EXPECT_EQ(SimMount("no-port", 100, 1).code(), StatusCode::kInvalidArgument);
}

// The sample-fixed method on brdf-sim: a relocate_lamp_and_detector prompt's target reaches the
// hook's environment, and from there the placed-by-hand registers (1, then signed centidegrees).
TEST(SimMount, PlacesLampAndDetectorAtThePromptsTarget) {
  v1::Prompt prompt;
  prompt.set_kind(v1::PROMPT_KIND_RELOCATE_LAMP_AND_DETECTOR);
  v1::Directions* t = prompt.mutable_target();
  t->set_theta_i(60);
  t->set_theta_o(30);
  t->set_phi_o(-150.25);
  std::vector<std::pair<std::string, std::string>> env = PromptEnvironment("7", prompt);
  for (const auto& [name, value] : env) ASSERT_EQ(::setenv(name.c_str(), value.c_str(), 1), 0);
  auto placed = PlacedFromPromptEnvironment();
  ASSERT_TRUE(placed.ok()) << placed.status().ToString();
  EXPECT_EQ(*placed, (Directions{60, 0, 30, -150.25}));
  auto regs = PlacedRegisters(*placed);
  ASSERT_TRUE(regs.ok()) << regs.status().ToString();
  EXPECT_EQ(*regs, (std::vector<std::uint16_t>{1, 6000, 0, 3000,
                                               static_cast<std::uint16_t>(std::int16_t{-15025})}));

  auto behind = PlacedRegisters(Directions{60, 0, 95, 0});
  EXPECT_EQ(behind.status().code(), StatusCode::kInvalidArgument);
  EXPECT_NE(behind.status().message().find("θo"), std::string::npos) << behind.status().message();

  // A prompt without a target (a sample-rotation rig's) sets none of them.
  v1::Prompt relocate;
  relocate.set_kind(v1::PROMPT_KIND_RELOCATE_DETECTOR);
  for (const auto& [name, value] : PromptEnvironment("7", relocate)) {
    EXPECT_EQ(name.find("BRDF_PROMPT_THETA"), std::string::npos) << name;
  }
  ASSERT_EQ(::unsetenv("BRDF_PROMPT_PHI_O"), 0);
  auto missing = PlacedFromPromptEnvironment();
  EXPECT_EQ(missing.status().code(), StatusCode::kInvalidArgument);
  EXPECT_NE(missing.status().message().find("BRDF_PROMPT_PHI_O"), std::string::npos);
  for (const auto& [name, value] : env) ::unsetenv(name.c_str());
}

}  // namespace
}  // namespace brdf::ctl

namespace brdf::ctl {
namespace {

std::string ExampleConfigPath() {
#ifdef BRDF_TEST_SOURCE_DIR
  const std::string source = BRDF_TEST_SOURCE_DIR;
#else
  const char* env = std::getenv("BRDF_SOURCE_DIR");
  const std::string source = env != nullptr ? env : ".";
#endif
  return source + "/deploy/brdfd.example.toml";
}

std::string ExampleConfigText() {
  std::ifstream in(ExampleConfigPath());
  std::ostringstream text;
  text << in.rdbuf();
  return text.str();
}

// deploy/brdfd.example.toml is what an installer copies; it must load as it is, and its values
// are the daemon's defaults.
TEST(ExampleConfig, LoadsAndHoldsTheDefaults) {
  const std::string text = ExampleConfigText();
  ASSERT_FALSE(text.empty()) << ExampleConfigPath() << " not found";
  Result<daemon::Config> config = daemon::ParseConfig(text, "brdfd.example.toml");
  ASSERT_TRUE(config.ok()) << config.status().ToString();
  const daemon::Config defaults;
  EXPECT_EQ(config->server.listen, defaults.server.listen);
  EXPECT_FALSE(config->server.tls.has_value());
  EXPECT_EQ(config->storage.database, defaults.storage.database);
  EXPECT_EQ(config->meter.port, defaults.meter.port);
  EXPECT_EQ(config->meter.pacing_ms, defaults.meter.pacing_ms);
  EXPECT_EQ(config->meter.measurement_timeout_ms, defaults.meter.measurement_timeout_ms);
  EXPECT_EQ(config->meter.overhead_ms, defaults.meter.overhead_ms);
  EXPECT_EQ(config->meter.adaptive_reference_ms, defaults.meter.adaptive_reference_ms);
  EXPECT_EQ(config->meter.adaptive_dark_ms, defaults.meter.adaptive_dark_ms);
  EXPECT_EQ(config->meter.adaptive_sample_ms, defaults.meter.adaptive_sample_ms);
  EXPECT_TRUE(config->meter.quality_overrides.empty());
  EXPECT_EQ(config->stage.profile, defaults.stage.profile);
  EXPECT_EQ(config->stage.detector_arm_motorized, defaults.stage.detector_arm_motorized);
  EXPECT_DOUBLE_EQ(config->stage.alpha.counts_per_degree, defaults.stage.alpha.counts_per_degree);
  EXPECT_DOUBLE_EQ(config->stage.beta.speed_deg_s, defaults.stage.beta.speed_deg_s);
  EXPECT_EQ(config->stage.gamma.present, defaults.stage.gamma.present);
  EXPECT_DOUBLE_EQ(config->sample.white_reflectance, defaults.sample.white_reflectance);
  EXPECT_EQ(config->index.max_sessions, defaults.index.max_sessions);
  EXPECT_EQ(config->exports.max_entries, defaults.exports.max_entries);
  EXPECT_EQ(config->exports.max_mb, defaults.exports.max_mb);
  EXPECT_TRUE(config->tokens.empty());
  EXPECT_EQ(config->log.level, defaults.log.level);
}

// Its commented-out examples are valid too once uncommented: the tokens, the quality rules.
TEST(ExampleConfig, CommentedExamplesParseWhenUncommented) {
  std::istringstream in(ExampleConfigText());
  std::string line, out;
  bool in_tokens = false;
  while (std::getline(in, line)) {
    if (line.rfind("# [[auth.tokens]]", 0) == 0) in_tokens = true;
    const bool quality_rule = line.rfind("# \"18\"", 0) == 0 || line.rfind("# \"30\"", 0) == 0;
    const bool token_key =
        in_tokens && (line.rfind("# name", 0) == 0 || line.rfind("# token", 0) == 0 ||
                      line.rfind("# role", 0) == 0 || line.rfind("# [[auth.tokens]]", 0) == 0);
    out += (quality_rule || token_key ? line.substr(2) : line) + "\n";
  }
  Result<daemon::Config> config = daemon::ParseConfig(out, "uncommented example");
  ASSERT_TRUE(config.ok()) << config.status().ToString();
  ASSERT_EQ(config->tokens.size(), 2u);
  EXPECT_EQ(config->tokens[0].role, daemon::Role::kOperator);
  EXPECT_EQ(config->tokens[1].role, daemon::Role::kAnalyst);
  EXPECT_EQ(config->meter.quality_overrides.size(), 2u);
}

}  // namespace
}  // namespace brdf::ctl
