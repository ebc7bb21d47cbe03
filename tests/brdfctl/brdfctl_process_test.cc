// brdfctl as a user runs it: the built executable against a running brdfd and brdf-sim
// (processes), checked by its exit status and what it prints.
#include <google/protobuf/util/json_util.h>
#include <gtest/gtest.h>

#include <cctype>
#include <cmath>
#include <cstdlib>
#include <fstream>
#include <map>
#include <memory>
#include <optional>
#include <sstream>

#include "brdf/v1/brdf.pb.h"
#include "tests/brdfctl/ctl_test_rig.h"
#include "tests/support/test_env.h"
#include "tools/brdf-sim/optics/optics.h"

namespace brdf::testing {
namespace {

using namespace std::chrono_literals;

// Parses one line of --json output strictly (unknown fields refused), as the type it claims to be.
template <typename Message>
std::optional<Message> ParseJson(const std::string& line) {
  Message m;
  google::protobuf::util::JsonParseOptions options;
  options.ignore_unknown_fields = false;
  if (!google::protobuf::util::JsonStringToMessage(line, &m, options).ok()) return std::nullopt;
  return m;
}

std::string Describe(const CommandResult& r) {
  return "exit " + std::to_string(r.exit_code) + "\n--- stdout:\n" + r.out + "\n--- stderr:\n" +
         r.err;
}

std::string WriteFile(const TempDir& dir, const std::string& name, const std::string& text) {
  const std::string path = dir.file(name).string();
  std::ofstream(path) << text;
  return path;
}

// The demo session of deploy/quickstart.sh (examples/plans/demo.json), submitted and watched to
// its end with --auto-confirm, the operator's actions done by `sim-mount from-prompt`. Run once
// for the suite; tests that need a finished session share it.
struct WatchedSession {
  std::string id;
  CommandResult submit;
  CommandResult watch;
};

class BrdfctlProcessTest : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    rig_ = new CtlRig();
    const Status started = rig_->Start();
    if (!started.ok()) start_error_ = new std::string(started.ToString());
  }
  static void TearDownTestSuite() {
    delete watched_;
    watched_ = nullptr;
    delete rig_;
    rig_ = nullptr;
    delete start_error_;
    start_error_ = nullptr;
  }
  void SetUp() override {
    if (start_error_ != nullptr) GTEST_FAIL() << "the rig did not start: " << *start_error_;
  }

  static CommandResult Ctl(const std::vector<std::string>& args,
                           const std::string& token = kCtlOperatorToken,
                           std::chrono::milliseconds timeout = 30s) {
    Result<CommandResult> r = rig_->Ctl(args, token, timeout);
    EXPECT_TRUE(r.ok()) << r.status().ToString();
    return r.ok() ? *r : CommandResult{-1, "", r.status().ToString()};
  }

  static const WatchedSession& Watched() {
    if (watched_ != nullptr) return *watched_;
    watched_ = new WatchedSession;
    watched_->submit =
        Ctl({"submit", SourceDir() + "/examples/plans/demo.json", "--start", "--quiet"});
    Lines(watched_->submit.out).swap(submit_lines_);
    if (watched_->submit.exit_code == 0 && submit_lines_.size() == 1) {
      watched_->id = submit_lines_[0];
      const std::string ctl = *BrdfctlBinary();
      watched_->watch = Ctl({"watch", watched_->id, "--auto-confirm", "--json", "--on-prompt",
                             "'" + ctl + "' sim-mount from-prompt --modbus " + rig_->modbus()},
                            kCtlOperatorToken, 90s);
    }
    return *watched_;
  }

  void CheckSubmitAndWatch();
  void CheckPromptHookActions();
  void CheckInterpolate();
  void CheckInterpolateOutside();

  static CtlRig* rig_;
  static std::string* start_error_;
  static WatchedSession* watched_;
  static std::vector<std::string> submit_lines_;
};

CtlRig* BrdfctlProcessTest::rig_ = nullptr;
std::string* BrdfctlProcessTest::start_error_ = nullptr;
WatchedSession* BrdfctlProcessTest::watched_ = nullptr;
std::vector<std::string> BrdfctlProcessTest::submit_lines_;

TEST_F(BrdfctlProcessTest, ValidateGoodPlanPrintsSummaryAndExitsZero) {
  const CommandResult r = Ctl({"validate", SourceDir() + "/examples/plans/demo.json"});
  EXPECT_EQ(r.exit_code, 0) << Describe(r);
  EXPECT_NE(r.out.find("valid"), std::string::npos) << Describe(r);
  EXPECT_NE(r.out.find("steps"), std::string::npos) << Describe(r);
}

TEST_F(BrdfctlProcessTest, ValidateBadPlanPrintsEveryProblemWithFieldPathsAndExitsTwo) {
  TempDir dir("brdfctl-plan");
  const std::string path = WriteFile(dir, "bad.json", R"({
    "name": "four mistakes",
    "sampleRotation": {
      "delta": {"start": 0, "stop": 200, "step": 22.5},
      "alpha": {"step": -10}
    },
    "measurement": {"averages": 500},
    "retry": {"maxAttempts": 50}
  })");
  const CommandResult r = Ctl({"validate", path});
  EXPECT_EQ(r.exit_code, 2) << Describe(r);
  for (const char* field : {"sampleRotation.delta.stop", "sampleRotation.alpha.step",
                            "measurement.averages", "retry.maxAttempts"}) {
    EXPECT_NE(r.out.find(std::string("  ") + field + ": "), std::string::npos)
        << "no problem line for " << field << "\n"
        << Describe(r);
  }

  // The same as data: one ValidatePlanResponse naming the same fields.
  const CommandResult j = Ctl({"validate", path, "--json"});
  EXPECT_EQ(j.exit_code, 2) << Describe(j);
  const std::vector<std::string> lines = Lines(j.out);
  ASSERT_EQ(lines.size(), 1u) << Describe(j);
  const auto reply = ParseJson<v1::ValidatePlanResponse>(lines[0]);
  ASSERT_TRUE(reply.has_value()) << lines[0];
  EXPECT_FALSE(reply->valid());
  std::map<std::string, int> paths;
  for (const v1::PlanProblem& p : reply->problems()) ++paths[p.field_path()];
  for (const char* field : {"sampleRotation.delta.stop", "sampleRotation.alpha.step",
                            "measurement.averages", "retry.maxAttempts"}) {
    EXPECT_GE(paths[field], 1) << field << " missing from " << lines[0];
  }
}

TEST_F(BrdfctlProcessTest, PlanThatDoesNotParseNamesFileAndFieldAndExitsTwo) {
  TempDir dir("brdfctl-plan");
  const std::string path =
      WriteFile(dir, "typo.json", R"({"name": "typo", "sampleRotation": {"alpa": {}}})");
  for (const char* verb : {"validate", "submit"}) {
    const CommandResult r = Ctl({verb, path});
    EXPECT_EQ(r.exit_code, 2) << verb << ": " << Describe(r);
    EXPECT_NE(r.err.find(path), std::string::npos) << Describe(r);
    EXPECT_NE(r.err.find("sampleRotation.alpa"), std::string::npos) << Describe(r);
  }
  const CommandResult missing = Ctl({"validate", dir.file("nope.json").string()});
  EXPECT_EQ(missing.exit_code, 2) << Describe(missing);
  EXPECT_NE(missing.err.find("nope.json"), std::string::npos) << Describe(missing);
}

// submit --start --quiet, then watch --auto-confirm --json: the demo runs to completion, and every
// line of the output is a SessionEvent.
void BrdfctlProcessTest::CheckSubmitAndWatch() {
  const WatchedSession& w = Watched();
  ASSERT_EQ(w.submit.exit_code, 0) << Describe(w.submit);
  ASSERT_FALSE(w.id.empty()) << "submit --quiet must print only the id\n" << Describe(w.submit);
  ASSERT_EQ(w.watch.exit_code, 0) << Describe(w.watch) << "\nbrdfd's log:\n" << rig_->log();

  // Every line is one SessionEvent; the first a snapshot, the session completed at the end.
  const std::vector<std::string> lines = Lines(w.watch.out);
  ASSERT_FALSE(lines.empty());
  std::vector<v1::SessionEvent> events;
  for (const std::string& line : lines) {
    const auto event = ParseJson<v1::SessionEvent>(line);
    ASSERT_TRUE(event.has_value()) << "not a SessionEvent: " << line;
    EXPECT_EQ(event->session_id(), w.id);
    events.push_back(*event);
  }
  EXPECT_TRUE(events.front().has_snapshot()) << lines.front();
  std::optional<v1::SessionState> last_state;
  std::map<int, v1::PromptKind> prompts;
  std::map<int, v1::StepKind> completed;
  std::uint32_t done = 0, total = 0;
  for (const v1::SessionEvent& e : events) {
    if (e.has_state_changed()) last_state = e.state_changed().to();
    if (e.has_prompt()) prompts[e.prompt().step_index()] = e.prompt().kind();
    if (e.has_step_completed()) {
      completed[e.step_completed().step_index()] = e.step_completed().kind();
      done = e.step_completed().progress().done_steps();
      total = e.step_completed().progress().total_steps();
    }
  }
  ASSERT_TRUE(last_state.has_value());
  EXPECT_EQ(*last_state, v1::SESSION_STATE_COMPLETED);
  EXPECT_GT(total, 0u);
  EXPECT_EQ(done, total);
  // Every prompt was answered: its step completed.
  EXPECT_FALSE(prompts.empty());
  for (const auto& [step, kind] : prompts) {
    EXPECT_EQ(completed.count(step), 1u) << "prompt at step " << step << " never completed";
  }
  // The notes go to stderr, so that stdout stays JSON.
  EXPECT_NE(w.watch.err.find("confirmed"), std::string::npos) << Describe(w.watch);

  // GetSession agrees.
  const CommandResult get = Ctl({"get", w.id, "--json"});
  ASSERT_EQ(get.exit_code, 0) << Describe(get);
  const auto session = ParseJson<v1::Session>(Lines(get.out).at(0));
  ASSERT_TRUE(session.has_value()) << get.out;
  EXPECT_EQ(session->state(), v1::SESSION_STATE_COMPLETED);

  // Its history (ListSessionEvents): one JSON object per event, oldest first, queued to
  // completed; the text shows one line per event with the state's word, for an analyst too.
  const CommandResult history = Ctl({"events", w.id, "--json"}, kCtlAnalystToken);
  ASSERT_EQ(history.exit_code, 0) << Describe(history);
  const std::vector<std::string> history_lines = Lines(history.out);
  ASSERT_GE(history_lines.size(), 3u) << history.out;
  std::vector<v1::SessionStateEvent> states;
  for (const std::string& line : history_lines) {
    const auto event = ParseJson<v1::SessionStateEvent>(line);
    ASSERT_TRUE(event.has_value()) << "not a SessionStateEvent: " << line;
    states.push_back(*event);
  }
  EXPECT_EQ(states.front().state(), v1::SESSION_STATE_QUEUED);
  EXPECT_EQ(states.back().state(), v1::SESSION_STATE_COMPLETED);
  const CommandResult history_text = Ctl({"events", w.id});
  ASSERT_EQ(history_text.exit_code, 0) << Describe(history_text);
  const std::vector<std::string> text_lines = Lines(history_text.out);
  ASSERT_EQ(text_lines.size(), history_lines.size()) << history_text.out;
  EXPECT_NE(text_lines.front().find("  queued"), std::string::npos) << history_text.out;
  EXPECT_NE(text_lines.back().find("  completed"), std::string::npos) << history_text.out;
  // "YYYY-MM-DD hh:mm:ss ±hhmm  state  reason".
  EXPECT_TRUE(text_lines.front().size() > 25 && text_lines.front()[4] == '-' &&
              text_lines.front()[13] == ':' && text_lines.front()[19] == ' ' &&
              (text_lines.front()[20] == '+' || text_lines.front()[20] == '-'))
      << "a local time first: " << text_lines.front();

  // A fixed plan has no rounds: `rounds` says so and exits 2 (web/test/adaptive.mjs runs it on an
  // adaptive session).
  const CommandResult rounds = Ctl({"rounds", w.id}, kCtlAnalystToken);
  EXPECT_EQ(rounds.exit_code, 2) << Describe(rounds);
  EXPECT_NE(rounds.err.find("is not adaptive"), std::string::npos) << Describe(rounds);

  // Watching a finished session: the snapshot, then the stream ends; plain lines off a terminal.
  const CommandResult again = Ctl({"watch", w.id}, kCtlAnalystToken);
  EXPECT_EQ(again.exit_code, 0) << Describe(again);
  EXPECT_NE(again.out.find("completed"), std::string::npos) << Describe(again);
  EXPECT_EQ(again.out.find("\x1b["), std::string::npos) << "no terminal codes in a pipe";
}

// --on-prompt "brdfctl sim-mount from-prompt": the operator's actions happened on the simulator.
void BrdfctlProcessTest::CheckPromptHookActions() {
  const WatchedSession& w = Watched();
  ASSERT_EQ(w.watch.exit_code, 0) << Describe(w.watch);
  // The last prompt of the demo mounts the sample again.
  Result<sim::MountedTarget> mounted = rig_->sim_control().Mounted();
  ASSERT_TRUE(mounted.ok()) << mounted.status().ToString();
  EXPECT_EQ(*mounted, sim::MountedTarget::kSample);

  // Whites were measured with the white mounted and darks with the shutter closed: every dark is
  // far dimmer than every reference (had the hook done nothing, both would see the lit sample).
  const CommandResult r = Ctl({"readings", w.id, "--kind", "reference,dark", "--json"});
  ASSERT_EQ(r.exit_code, 0) << Describe(r);
  double dimmest_reference = 1e300, brightest_dark = 0;
  int references = 0, darks = 0;
  for (const std::string& line : Lines(r.out)) {
    const auto reading = ParseJson<v1::Reading>(line);
    ASSERT_TRUE(reading.has_value()) << line;
    ASSERT_EQ(reading->radiance_size(), 101) << line;
    const double at_560 = reading->radiance(45);  // 380 + 45 · 4 nm
    if (reading->kind() == v1::READING_KIND_REFERENCE) {
      ++references;
      dimmest_reference = std::min(dimmest_reference, at_560);
    } else {
      ASSERT_EQ(reading->kind(), v1::READING_KIND_DARK);
      ++darks;
      brightest_dark = std::max(brightest_dark, at_560);
    }
  }
  EXPECT_GT(references, 0);
  EXPECT_GT(darks, 0);
  EXPECT_GT(dimmest_reference, 100 * brightest_dark);
}

// interpolate --explain: the spectrum, its vertices and weights; close to the ground truth.
void BrdfctlProcessTest::CheckInterpolate() {
  const WatchedSession& w = Watched();
  ASSERT_EQ(w.watch.exit_code, 0) << Describe(w.watch);
  // The quick start's direction, between the demo grid's samples.
  const CommandResult r =
      Ctl({"interpolate", w.id, "--theta-i", "35", "--theta-o", "40", "--phi", "40", "--explain"},
          kCtlAnalystToken);
  ASSERT_EQ(r.exit_code, 0) << Describe(r);
  EXPECT_NE(r.out.find("octant: ok"), std::string::npos) << Describe(r);

  // The table: one row per band, 380 … 780 nm, the interpolated value, its expanded
  // uncertainties (± measurement, ± interpolation, ± total; k = 2), then four vertex values.
  std::vector<std::pair<double, std::vector<double>>> rows;
  double weight_sum = -1;
  int vertices = 0;
  for (const std::string& line : Lines(r.out)) {
    std::istringstream in(line);
    std::string first;
    in >> first;
    if (first.size() == 2 && first[0] == 'v' &&
        std::isdigit(static_cast<unsigned char>(first[1]))) {
      ++vertices;
    }
    if (line.find("weights sum to") != std::string::npos) {
      weight_sum = std::stod(line.substr(line.find("to") + 3));
    }
    char* end = nullptr;
    const double nm = std::strtod(first.c_str(), &end);
    if (first.empty() || *end != '\0') continue;
    std::vector<double> values;
    std::string cell;
    while (in >> cell) {
      if (cell.rfind("±", 0) == 0) cell = cell.substr(std::string("±").size());
      values.push_back(std::strtod(cell.c_str(), &end));
      if (*end != '\0') break;
    }
    rows.emplace_back(nm, values);
  }
  EXPECT_EQ(vertices, 4) << Describe(r);
  EXPECT_NEAR(weight_sum, 1.0, 1e-6) << Describe(r);
  ASSERT_EQ(rows.size(), 101u) << Describe(r);
  EXPECT_DOUBLE_EQ(rows.front().first, 380);
  EXPECT_DOUBLE_EQ(rows.back().first, 780);
  for (const auto& [nm, values] : rows) {
    ASSERT_EQ(values.size(), 8u) << "at " << nm << " nm";
    for (double v : values) EXPECT_TRUE(std::isfinite(v) && v >= 0) << v << " at " << nm << " nm";
    EXPECT_GT(values[0], 0) << "at " << nm << " nm";
    EXPECT_GT(values[1], 0) << "a measurement uncertainty at " << nm << " nm";
    // The total is the quadrature sum of the two (each printed to 3 digits).
    EXPECT_NEAR(values[3], std::hypot(values[1], values[2]), 0.01 * values[3]) << nm << " nm";
  }

  // And it is the sample's BRDF: within 25 % of the simulator's ground truth at 560 nm.
  Result<CommandResult> truth =
      RunBrdfSim({"truth", "--theta-i", "35", "--theta-o", "40", "--phi", "40"});
  ASSERT_TRUE(truth.ok()) << truth.status().ToString();
  double true_560 = 0;
  for (const std::string& line : Lines(truth->out)) {
    std::istringstream in(line);
    double nm = 0, value = 0;
    if (line.empty() || line[0] == '#' || !(in >> nm >> value)) continue;
    if (nm == 560) true_560 = value;
  }
  ASSERT_GT(true_560, 0) << truth->out;
  EXPECT_NEAR(rows[45].second[0], true_560, 0.25 * true_560);

  // --json: one InterpolateResponse, then one InterpolationResult per vertex.
  const CommandResult j = Ctl({"interpolate", w.id, "--theta-i", "35", "--theta-o", "40", "--phi",
                               "40", "--explain", "--json"},
                              kCtlAnalystToken);
  ASSERT_EQ(j.exit_code, 0) << Describe(j);
  const std::vector<std::string> lines = Lines(j.out);
  ASSERT_EQ(lines.size(), 5u) << Describe(j);
  const auto reply = ParseJson<v1::InterpolateResponse>(lines[0]);
  ASSERT_TRUE(reply.has_value()) << lines[0];
  ASSERT_EQ(reply->result().spectrum_size(), 101);
  EXPECT_NEAR(reply->result().spectrum(45), rows[45].second[0],
              1e-5 * std::fabs(rows[45].second[0]));
  // The JSON carries the uncertainty the table shows (k = 2 there, standard here).
  ASSERT_EQ(reply->result().uncertainty().combined_size(), 101);
  EXPECT_NEAR(2 * reply->result().uncertainty().combined(45), rows[45].second[3],
              0.01 * rows[45].second[3]);
}

// interpolate where the method cannot: exit 4 with the status.
void BrdfctlProcessTest::CheckInterpolateOutside() {
  const WatchedSession& w = Watched();
  ASSERT_EQ(w.watch.exit_code, 0) << Describe(w.watch);
  // The demo grid has hardly anything on the specular side at large angles.
  const CommandResult r = Ctl({"interpolate", w.id, "--theta-i", "80", "--theta-o", "80", "--phi",
                               "180", "--method", "delaunay"});
  EXPECT_EQ(r.exit_code, 4) << Describe(r);
  EXPECT_NE(r.err.find("outside_hull"), std::string::npos) << Describe(r);
  // A measured retro-plane direction the octant method cannot enclose: the readings mirrored to
  // −φ fill it, and the hint says so (the daemon answers with --mirror-phi).
  const CommandResult retro =
      Ctl({"interpolate", w.id, "--theta-i", "30", "--theta-o", "30", "--phi", "180"});
  EXPECT_EQ(retro.exit_code, 4) << Describe(retro);
  EXPECT_NE(retro.err.find("empty_octant"), std::string::npos) << Describe(retro);
  EXPECT_NE(retro.err.find("--mirror-phi fills it"), std::string::npos) << Describe(retro);
  const CommandResult filled = Ctl(
      {"interpolate", w.id, "--theta-i", "30", "--theta-o", "30", "--phi", "180", "--mirror-phi"});
  EXPECT_EQ(filled.exit_code, 0) << Describe(filled);
  // Where no symmetry helps, the hint says what else to try.
  const CommandResult corner =
      Ctl({"interpolate", w.id, "--theta-i", "20", "--theta-o", "70", "--phi", "180"});
  EXPECT_EQ(corner.exit_code, 4) << Describe(corner);
  EXPECT_NE(corner.err.find("try --method nearest"), std::string::npos) << Describe(corner);
  EXPECT_EQ(corner.err.find("fills it"), std::string::npos) << Describe(corner);
}

// The quick start's demo plan (examples/plans/demo.json) through brdfctl, end to end. One test,
// because the session takes most of the suite's time (ctest runs every test in its own process).
TEST_F(BrdfctlProcessTest, DemoPlanSubmitWatchAutoConfirmAndInterpolate) {
  {
    SCOPED_TRACE("submit and watch");
    CheckSubmitAndWatch();
  }
  {
    SCOPED_TRACE("the --on-prompt hook");
    CheckPromptHookActions();
  }
  {
    SCOPED_TRACE("interpolate");
    CheckInterpolate();
  }
  {
    SCOPED_TRACE("interpolate outside the data");
    CheckInterpolateOutside();
  }
}

// The adaptive plan in the sample-fixed method's form (the panel stays put; each pose a
// relocate_lamp_and_detector prompt) on brdf-sim: `sim-mount from-prompt` places lamp and detector
// at each prompt's target, so every sample reading is the virtual sample's BRDF at its recorded
// directions (without the placement the simulator would read at the holder's rest pose: errors of
// 100 % and more).
TEST_F(BrdfctlProcessTest, AdaptiveSampleFixedOnTheSimulatorReadsTheTargetsDirections) {
  TempDir dir("brdfctl-sample-fixed");
  const std::string plan = WriteFile(dir, "plan.json", R"({
  "name": "adaptive sample-fixed on brdf-sim",
  "adaptive": {
    "target": {"expandedUncertainty": 0.001},
    "budget": {"maxPrompts": 18},
    "region": {"thetaIMaxDeg": 70, "thetaOMaxDeg": 70},
    "seed": {"retroReadings": 2},
    "sampleFixed": {"seedReadings": 6},
    "roundReadings": 4
  },
  "reference": {"perDetectorPosition": false, "everyMinutes": 15},
  "measurement": {"integrationMs": 100, "averages": 1}
})");
  const CommandResult submit = Ctl({"submit", plan, "--start", "--quiet"});
  ASSERT_EQ(submit.exit_code, 0) << Describe(submit);
  const std::string id = Lines(submit.out).at(0);
  const std::string ctl = *BrdfctlBinary();
  const CommandResult watch =
      Ctl({"watch", id, "--auto-confirm", "--on-prompt",
           "'" + ctl + "' sim-mount from-prompt --modbus " + rig_->modbus()},
          kCtlOperatorToken, 100s);
  ASSERT_EQ(watch.exit_code, 0) << Describe(watch) << rig_->log();
  EXPECT_NE(watch.err.find("placed by hand"), std::string::npos) << Describe(watch);

  const CommandResult r = Ctl({"readings", id, "--kind", "sample", "--json"});
  ASSERT_EQ(r.exit_code, 0) << Describe(r);
  int samples = 0;
  for (const std::string& line : Lines(r.out)) {
    const auto reading = ParseJson<v1::Reading>(line);
    ASSERT_TRUE(reading.has_value()) << line;
    ASSERT_TRUE(reading->has_uncertainty()) << line;
    const v1::Directions& d = reading->directions();
    const std::vector<double> truth = sim::TrueBrdf(
        Directions{d.theta_i(), d.phi_i(), d.theta_o(), d.phi_o()}, /*anisotropic=*/false);
    const auto& f = reading->uncertainty().value();
    ASSERT_EQ(f.size(), static_cast<int>(truth.size())) << line;
    for (int k : {20, 42, 70}) {  // 460, 548 and 660 nm
      EXPECT_NEAR(f[k], truth[static_cast<std::size_t>(k)],
                  0.05 * truth[static_cast<std::size_t>(k)])
          << "reading " << reading->id() << " at θi " << d.theta_i() << " θo " << d.theta_o()
          << " φo " << d.phi_o() << ", band " << k;
    }
    ++samples;
  }
  EXPECT_GE(samples, 8) << Describe(r);
}

TEST_F(BrdfctlProcessTest, WrongTokenExitsThreeWithAClearMessage) {
  const CommandResult wrong = Ctl({"list"}, "not-a-token-of-this-daemon");
  EXPECT_EQ(wrong.exit_code, 3) << Describe(wrong);
  EXPECT_NE(wrong.err.find("UNAUTHENTICATED"), std::string::npos) << Describe(wrong);
  EXPECT_NE(wrong.err.find("BRDF_TOKEN"), std::string::npos) << Describe(wrong);
  EXPECT_TRUE(wrong.out.empty()) << Describe(wrong);

  const CommandResult none = Ctl({"list"}, "");
  EXPECT_EQ(none.exit_code, 3) << Describe(none);
  EXPECT_NE(none.err.find("UNAUTHENTICATED"), std::string::npos) << Describe(none);

  // --token overrides BRDF_TOKEN.
  const CommandResult flag =
      Ctl({"list", "--token", kCtlOperatorToken}, "not-a-token-of-this-daemon");
  EXPECT_EQ(flag.exit_code, 0) << Describe(flag);

  // An analyst may read but not control.
  const CommandResult analyst = Ctl({"abort", "1", "--reason", "test"}, kCtlAnalystToken);
  EXPECT_EQ(analyst.exit_code, 3) << Describe(analyst);
  EXPECT_NE(analyst.err.find("PERMISSION_DENIED"), std::string::npos) << Describe(analyst);
  EXPECT_EQ(Ctl({"list"}, kCtlAnalystToken).exit_code, 0);
}

TEST_F(BrdfctlProcessTest, RigShowsBothDevicesConnected) {
  const CommandResult r = Ctl({"rig"}, kCtlAnalystToken);
  ASSERT_EQ(r.exit_code, 0) << Describe(r);
  EXPECT_NE(r.out.find("meter: connected"), std::string::npos) << Describe(r);
  EXPECT_NE(r.out.find("stage: connected"), std::string::npos) << Describe(r);
  const CommandResult j = Ctl({"rig", "--json"}, kCtlAnalystToken);
  ASSERT_EQ(j.exit_code, 0) << Describe(j);
  const auto status = ParseJson<v1::RigStatus>(Lines(j.out).at(0));
  ASSERT_TRUE(status.has_value()) << j.out;
  EXPECT_TRUE(status->detector_arm_motorized());
}

TEST_F(BrdfctlProcessTest, VerbsOnAnUnknownSessionExitOneWithNotFound) {
  const CommandResult r = Ctl({"get", "999999"});
  EXPECT_EQ(r.exit_code, 1) << Describe(r);
  EXPECT_NE(r.err.find("NOT_FOUND"), std::string::npos) << Describe(r);
  const CommandResult events = Ctl({"events", "999999"});
  EXPECT_EQ(events.exit_code, 1) << Describe(events);
  EXPECT_NE(events.err.find("NOT_FOUND"), std::string::npos) << Describe(events);
  EXPECT_NE(events.err.find("ListSessionEvents"), std::string::npos) << Describe(events);
  const CommandResult rounds = Ctl({"rounds", "999999"});
  EXPECT_EQ(rounds.exit_code, 1) << Describe(rounds);
  EXPECT_NE(rounds.err.find("NOT_FOUND"), std::string::npos) << Describe(rounds);
}

TEST_F(BrdfctlProcessTest, UnreachableDaemonExitsOneWithAHint) {
  Result<int> port = FreeTcpPort();
  ASSERT_TRUE(port.ok());
  Result<CommandResult> r = RunBrdfctl(
      {"list", "--timeout", "2"},
      {{"BRDF_ADDRESS", "127.0.0.1:" + std::to_string(*port)}, {"BRDF_TOKEN", kCtlOperatorToken}});
  ASSERT_TRUE(r.ok()) << r.status().ToString();
  EXPECT_EQ(r->exit_code, 1) << Describe(*r);
  EXPECT_NE(r->err.find("UNAVAILABLE"), std::string::npos) << Describe(*r);
  EXPECT_NE(r->err.find("BRDF_ADDRESS"), std::string::npos) << Describe(*r);
}

}  // namespace
}  // namespace brdf::testing
