// An adaptive session through the real binaries (docs/adaptive.md, "Rounds as steps"; issue 38's
// check): brdfd with its interpolated uncertainty model (daemon/rig/back_end.cc) on brdf-sim,
// driven over gRPC. brdfd is killed with SIGKILL in the middle of a round, restarted on the same
// database, and the session resumed: the rounds stored before the kill are kept as they were,
// later ones follow, the session completes with an adaptive stop, and every reading step holds
// exactly one reading, within the reading budget. A sample pose the meter overloads at is skipped
// and never chosen again (the session completes); a fixed plan still pauses on it.
#include <gtest/gtest.h>

#include <chrono>
#include <memory>
#include <optional>
#include <set>
#include <string>
#include <vector>

#include "storage/session_store.h"
#include "tests/daemon/sessions/rig_test.h"
#include "tests/support/daemon/test_util.h"

namespace brdf::testing {
namespace {

using namespace std::chrono_literals;

constexpr int kRoundReadings = 6;
constexpr int kMaxReadings = 33;  // the seed's 15 (if all fit) and three rounds of 6

// examples/plans/adaptive.json made small: three detector positions, a seed of 3 + 3 × 4, rounds
// of 6; the target is out of reach, so the reading budget (or an empty round) stops it. `policies`
// follow the adaptive block.
std::string SmallAdaptivePlan(const std::string& name, const std::string& policies) {
  return R"({
  "name": ")" +
         name + R"(",
  "adaptive": {
    "target": {"expandedUncertainty": 0.001},
    "budget": {"maxReadings": )" +
         std::to_string(kMaxReadings) + R"(},
    "region": {"thetaIMaxDeg": 80, "thetaOMaxDeg": 80},
    "method": "ADAPTIVE_JUDGE_OCTANT",
    "delta": {"start": 0, "stop": 22.5, "step": 11.25},
    "seed": {"retroReadings": 3, "readingsPerDelta": 4},
    "roundReadings": )" +
         std::to_string(kRoundReadings) + R"(
  },
  )" + policies +
         "\n}";
}

const std::string kAdaptivePlan = SmallAdaptivePlan("adaptive, killed mid-round", R"(
  "reference": {"perDetectorPosition": true},
  "measurement": {"integrationMs": 100, "averages": 1})");

// The same made to meet an overload: adaptive integration (the driver cannot shorten it, so a
// quality 19 fails the attempt at once), two attempts a step, and one reference (at the start),
// so every measurement after the first sample is a sample's.
const std::string kOverloadedAdaptivePlan = SmallAdaptivePlan("adaptive, an overloaded pose", R"(
  "reference": {"perDetectorPosition": false},
  "measurement": {"integrationMs": 0, "averages": 1},
  "retry": {"maxAttempts": 2, "backoffMs": 0})");

// A fixed plan with the same settings: twelve poses at one detector position.
const std::string kOverloadedFixedPlan = R"({
  "name": "fixed, an overloaded pose",
  "poseList": {"poses": [
    {"alpha": 0, "beta": 0, "delta": 40}, {"alpha": 0, "beta": 5, "delta": 40},
    {"alpha": 0, "beta": 10, "delta": 40}, {"alpha": 0, "beta": 15, "delta": 40},
    {"alpha": 0, "beta": 20, "delta": 40}, {"alpha": 0, "beta": 25, "delta": 40},
    {"alpha": 0, "beta": 30, "delta": 40}, {"alpha": 0, "beta": 35, "delta": 40},
    {"alpha": 0, "beta": 40, "delta": 40}, {"alpha": 0, "beta": 45, "delta": 40},
    {"alpha": 0, "beta": 50, "delta": 40}, {"alpha": 0, "beta": 55, "delta": 40}]},
  "measurement": {"integrationMs": 0, "averages": 1},
  "retry": {"maxAttempts": 2, "backoffMs": 0}
})";

// What `read` reads from the session store at `database` (a failure to open or read is a test
// failure, and gives T's empty value).
template <typename T, typename Read>
T FromStore(const std::string& database, const Read& read) {
  auto store = storage::SessionStore::Open(database);
  EXPECT_TRUE(store.ok()) << store.status().ToString();
  if (!store.ok()) return T{};
  Result<T> got = read(**store);
  EXPECT_TRUE(got.ok()) << got.status().ToString();
  return got.ok() ? *got : T{};
}

std::vector<storage::StepRecord> StoredSteps(const std::string& database, std::int64_t id) {
  return FromStore<std::vector<storage::StepRecord>>(
      database, [id](storage::SessionStore& s) { return s.GetSteps(id); });
}

std::vector<storage::RoundRecord> StoredRounds(const std::string& database, std::int64_t id) {
  return FromStore<std::vector<storage::RoundRecord>>(
      database, [id](storage::SessionStore& s) { return s.GetRounds(id); });
}

std::optional<int> FirstUnfinished(const std::string& database, std::int64_t id) {
  return FromStore<std::optional<int>>(
      database, [id](storage::SessionStore& s) { return s.FirstUnfinishedStep(id); });
}

void ExpectSameRound(const storage::RoundRecord& after, const storage::RoundRecord& before) {
  EXPECT_EQ(after.round, before.round);
  EXPECT_EQ(after.first_step, before.first_step) << "round " << before.round;
  EXPECT_EQ(after.step_count, before.step_count) << "round " << before.round;
  EXPECT_EQ(after.readings_used, before.readings_used) << "round " << before.round;
  EXPECT_EQ(after.predicted_gain, before.predicted_gain) << "round " << before.round;
  ASSERT_EQ(after.picks.size(), before.picks.size()) << "round " << before.round;
  for (std::size_t k = 0; k < before.picks.size(); ++k) {
    EXPECT_EQ(after.picks[k].pose, before.picks[k].pose) << "round " << before.round;
    EXPECT_EQ(after.picks[k].predicted_gain, before.picks[k].predicted_gain);
  }
}

class AdaptiveDaemonTest : public SessionRigTest {
 protected:
  // Once `id` has taken `samples` sample readings, the simulated PR-650 overloads (quality 19)
  // for its next two measurements: both attempts of the next sample step.
  void OverloadAfter(const std::string& id, int samples) {
    const v1::Session running = rig_.WaitFor(
        id,
        [&](const v1::Session& x) {
          return IsTerminal(x.state()) || static_cast<int>(x.progress().done_samples()) >= samples;
        },
        60s);
    ASSERT_FALSE(IsTerminal(running.state())) << running.DebugString();
    sim::SerialFaults faults;
    faults.quality_code = 19;
    faults.quality_count = 2;
    ASSERT_TRUE(rig_.sim_control().SetSerialFaults(faults).ok());
  }

  std::set<std::int64_t> ReadingIds(const std::string& id) {
    Result<std::vector<v1::Reading>> r = rig_.Readings(id);
    EXPECT_TRUE(r.ok()) << r.status().ToString();
    std::set<std::int64_t> ids;
    if (r.ok()) {
      for (const v1::Reading& x : *r) EXPECT_TRUE(ids.insert(x.id()).second) << x.id();
    }
    return ids;
  }
};

TEST_F(AdaptiveDaemonTest, KillNineMidRoundRestartResumeContinuesTheDesign) {
  Result<v1::Session> submitted = rig_.Submit(kAdaptivePlan);
  ASSERT_TRUE(submitted.ok()) << submitted.status().ToString();
  const std::string id = submitted->session_id();
  const std::int64_t sid = std::stoll(id);
  const int seed_samples = static_cast<int>(submitted->summary().sample_readings());
  ASSERT_GT(seed_samples, 0);
  ASSERT_LE(seed_samples, kMaxReadings - kRoundReadings);
  GrpcOperator& op = Watch(id);

  // One sample reading into the first round (6 readings, a few seconds of real time: a slow poll
  // still lands before the round's end).
  const v1::Session running = rig_.WaitFor(
      id,
      [&](const v1::Session& x) {
        return IsTerminal(x.state()) ||
               (x.state() == v1::SESSION_STATE_RUNNING &&
                static_cast<int>(x.progress().done_samples()) >= seed_samples + 1);
      },
      90s);
  ASSERT_EQ(running.state(), v1::SESSION_STATE_RUNNING) << running.DebugString() << rig_.log();
  op.Stop();
  rig_.KillDaemon();  // SIGKILL: no shutdown code runs

  // Killed mid-round: a round is stored and its steps are partly done.
  const std::vector<storage::RoundRecord> before = StoredRounds(rig_.database(), sid);
  ASSERT_GE(before.size(), 1u);
  const storage::RoundRecord& current = before.back();
  const std::optional<int> first_unfinished = FirstUnfinished(rig_.database(), sid);
  ASSERT_TRUE(first_unfinished.has_value());
  EXPECT_GT(*first_unfinished, current.first_step);
  EXPECT_LT(*first_unfinished, current.first_step + current.step_count);
  Result<DbSessionCounts> killed = CountSession(rig_.database(), sid);
  ASSERT_TRUE(killed.ok()) << killed.status().ToString();
  EXPECT_NE(killed->state, "completed");
  ExpectIntact(sid);

  Status restarted = rig_.StartDaemon();
  ASSERT_TRUE(restarted.ok()) << restarted.ToString();
  EXPECT_EQ(rig_.Get(id)->state(), v1::SESSION_STATE_PAUSED);
  const std::set<std::int64_t> readings_before = ReadingIds(id);
  EXPECT_EQ(static_cast<int>(readings_before.size()), killed->readings);

  GrpcOperator& resumed_op = Watch(id);
  v1::ResumeSessionRequest resume;
  resume.set_session_id(id);
  v1::ResumeSessionResponse resumed;
  grpc::Status st = rig_.control().ResumeSession(DaemonRig::Context().get(), resume, &resumed);
  ASSERT_TRUE(st.ok()) << st.error_message();
  const v1::Session done = rig_.WaitForState(id, v1::SESSION_STATE_COMPLETED, 90s);
  ASSERT_EQ(done.state(), v1::SESSION_STATE_COMPLETED) << done.DebugString() << rig_.log();
  EXPECT_EQ(done.state_reason().rfind("adaptive: ", 0), 0u) << done.state_reason();

  // The watcher after the restart saw the later rounds and the stop.
  std::vector<v1::AdaptiveRound> seen_rounds;
  std::vector<v1::AdaptiveStop> stops;
  for (const v1::SessionEvent& e : resumed_op.events()) {
    if (e.has_adaptive_round()) seen_rounds.push_back(e.adaptive_round());
    if (e.has_adaptive_stop()) stops.push_back(e.adaptive_stop());
  }
  ASSERT_EQ(stops.size(), 1u);
  EXPECT_FALSE(stops[0].reason().empty());
  EXPECT_NE(done.state_reason().find(stops[0].reason()), std::string::npos)
      << done.state_reason() << " / " << stops[0].reason();

  // The design continued: the rounds before the kill as they were, then later ones.
  const std::vector<storage::RoundRecord> after = StoredRounds(rig_.database(), sid);
  ASSERT_GT(after.size(), before.size());
  for (std::size_t i = 0; i < before.size(); ++i) ExpectSameRound(after[i], before[i]);
  int next_step = before.front().first_step;
  int samples_before_round = seed_samples;
  for (const storage::RoundRecord& r : after) {
    EXPECT_EQ(r.round, static_cast<int>(&r - after.data()) + 1);
    EXPECT_EQ(r.first_step, next_step) << "round " << r.round;
    EXPECT_EQ(r.readings_used, samples_before_round) << "round " << r.round;
    next_step = r.first_step + r.step_count;
    samples_before_round += static_cast<int>(r.picks.size());
  }
  EXPECT_EQ(stops[0].rounds(), after.size());
  EXPECT_EQ(static_cast<int>(stops[0].readings()), samples_before_round);

  // No reading lost or taken twice; within the budget.
  Result<DbSessionCounts> c = CountSession(rig_.database(), sid);
  ASSERT_TRUE(c.ok()) << c.status().ToString();
  EXPECT_EQ(c->steps_pending, 0);
  EXPECT_EQ(c->steps_done, c->total_steps);
  EXPECT_EQ(c->total_steps, next_step);
  EXPECT_EQ(c->duplicate_readings, 0);
  ExpectIntact(sid);
  const std::set<std::int64_t> readings_after = ReadingIds(id);
  for (std::int64_t r : readings_before) EXPECT_EQ(readings_after.count(r), 1u) << r;
  EXPECT_EQ(static_cast<int>(readings_after.size()), c->readings);
  EXPECT_EQ(static_cast<int>(done.progress().done_samples()), samples_before_round);
  EXPECT_LE(samples_before_round, kMaxReadings);
}

TEST_F(AdaptiveDaemonTest, AnOverloadedPoseIsSkippedNeverChosenAgainAndTheSessionCompletes) {
  Result<v1::Session> submitted = rig_.Submit(kOverloadedAdaptivePlan);
  ASSERT_TRUE(submitted.ok()) << submitted.status().ToString();
  const std::string id = submitted->session_id();
  const std::int64_t sid = std::stoll(id);
  GrpcOperator& op = Watch(id);
  OverloadAfter(id, 2);

  const v1::Session done = rig_.WaitForState(id, v1::SESSION_STATE_COMPLETED, 90s);
  ASSERT_EQ(done.state(), v1::SESSION_STATE_COMPLETED) << done.DebugString() << rig_.log();
  EXPECT_EQ(done.state_reason().rfind("adaptive: ", 0), 0u) << done.state_reason();

  // One sample step skipped, with why; every other step done, each measuring one with its reading.
  const std::vector<storage::StepRecord> steps = StoredSteps(rig_.database(), sid);
  std::vector<storage::StepRecord> skipped;
  for (const storage::StepRecord& s : steps) {
    if (s.state == storage::StepState::kSkipped)
      skipped.push_back(s);
    else
      EXPECT_EQ(s.state, storage::StepState::kDone) << "step " << s.step_index;
  }
  ASSERT_EQ(skipped.size(), 1u);
  const storage::StepRecord& lost = skipped.front();
  EXPECT_EQ(lost.kind, storage::StepKind::kSample);
  ASSERT_TRUE(lost.note.has_value());
  EXPECT_NE(lost.note->find("overload"), std::string::npos) << *lost.note;
  EXPECT_NE(lost.note->find("19"), std::string::npos) << *lost.note;
  Result<DbSessionCounts> c = CountSession(rig_.database(), sid);
  ASSERT_TRUE(c.ok()) << c.status().ToString();
  EXPECT_EQ(c->steps_pending, 0);
  EXPECT_EQ(c->steps_done + 1, c->total_steps);
  EXPECT_EQ(c->readings, c->measuring_steps_done);
  EXPECT_EQ(c->duplicate_readings, 0);
  EXPECT_EQ(c->orphan_readings, 0);
  Result<std::string> problems = StorageProblems(rig_.database(), sid);
  ASSERT_TRUE(problems.ok()) << problems.status().ToString();
  EXPECT_EQ(*problems, "");

  // The watchers heard which pose and why, as a fault that does not pause the session.
  std::vector<v1::Fault> skips;
  for (const v1::SessionEvent& e : op.events()) {
    if (e.has_fault() && e.fault().reason().rfind("step skipped: ", 0) == 0) {
      skips.push_back(e.fault());
    }
    if (e.has_state_changed()) {
      EXPECT_NE(e.state_changed().to(), v1::SESSION_STATE_PAUSED) << e.DebugString();
    }
  }
  ASSERT_EQ(skips.size(), 1u);
  EXPECT_EQ(skips[0].step_index(), lost.step_index);
  EXPECT_EQ(skips[0].device_code(), 19);
  EXPECT_FALSE(skips[0].will_retry());
  EXPECT_NE(skips[0].reason().find("δ"), std::string::npos) << skips[0].reason();

  // Never chosen again: no later step measures that pose, and a round followed the skip.
  bool round_after = false;
  for (const storage::StepRecord& s : steps) {
    if (s.step_index <= lost.step_index || s.kind != storage::StepKind::kSample) continue;
    round_after = true;
    EXPECT_FALSE(s.pose == lost.pose) << "step " << s.step_index << " measures it again";
  }
  EXPECT_TRUE(round_after);
}

TEST_F(AdaptiveDaemonTest, AFixedPlanStillPausesOnAnOverload) {
  Result<v1::Session> submitted = rig_.Submit(kOverloadedFixedPlan);
  ASSERT_TRUE(submitted.ok()) << submitted.status().ToString();
  const std::string id = submitted->session_id();
  Watch(id);
  OverloadAfter(id, 1);

  const v1::Session paused = rig_.WaitForState(id, v1::SESSION_STATE_PAUSED, 60s);
  ASSERT_EQ(paused.state(), v1::SESSION_STATE_PAUSED) << paused.DebugString() << rig_.log();
  ASSERT_TRUE(paused.has_last_fault());
  EXPECT_EQ(paused.last_fault().device_code(), 19);
  EXPECT_FALSE(paused.last_fault().will_retry());
  EXPECT_EQ(paused.last_fault().reason().rfind("step skipped: ", 0), std::string::npos);
  for (const storage::StepRecord& s : StoredSteps(rig_.database(), std::stoll(id))) {
    EXPECT_NE(s.state, storage::StepState::kSkipped) << "step " << s.step_index;
  }
  ExpectIntact(std::stoll(id));
}

}  // namespace
}  // namespace brdf::testing
