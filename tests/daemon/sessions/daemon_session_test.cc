// Sessions driven through brdfd's gRPC API end to end: brdf-sim and brdfd run as processes, the
// test is a gRPC client (and the operator at the rig, through the simulator's control unit),
// and the SQLite file is checked directly afterwards.
#include <gtest/gtest.h>
#include <signal.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdlib>
#include <fstream>
#include <map>
#include <set>
#include <sstream>
#include <thread>

#include "storage/session_store.h"
#include "tests/daemon/sessions/rig_test.h"
#include "tests/support/daemon/test_util.h"
#include "tests/support/plan_fixtures.h"

namespace brdf::testing {
namespace {

using namespace std::chrono_literals;

// Two detector positions, two tilts, β every 45° (within the default margin); a dark with each
// reference, so the operator mounts the white, closes the shutter and mounts the sample per δ.
const std::string kRotationPlan = plans::SmallRotation();

// Readings long enough (40 averages × 200 ms + 1 s overhead = 9 simulated seconds, ~0.18 s real)
// to be caught in the middle by an immediate pause. (A long integration instead would overload
// the detector near the highlight.)
const std::string kSlowPlan =
    plans::SlowRotation(/*alpha_stop=*/10, /*beta_step=*/30, /*averages=*/40);

const std::string kFixedPlan =
    plans::SampleFixed({{0, 45, 180, "0/45"}, {30, 30, 180, "specular 30"}, {20, 50, 90, "side"}},
                       /*reference_per_detector_position=*/true);

const std::string kTinyPlan = plans::TinyPoseList();

std::int64_t IdOf(const v1::Session& s) {
  return std::stoll(s.session_id());
}

class DaemonSessionTest : public SessionRigTest {
 protected:
  v1::Session SubmitAndWatch(const std::string& plan) {
    Result<v1::Session> s = rig_.Submit(plan);
    EXPECT_TRUE(s.ok()) << s.status().ToString();
    if (!s.ok()) return {};
    Watch(s->session_id());
    return *s;
  }

  std::vector<v1::Reading> Readings(const std::string& id) {
    Result<std::vector<v1::Reading>> r = rig_.Readings(id);
    EXPECT_TRUE(r.ok()) << r.status().ToString();
    return r.ok() ? *r : std::vector<v1::Reading>();
  }

  static int PlannedReadings(const v1::Session& s) {
    return static_cast<int>(s.summary().sample_readings() + s.summary().reference_readings() +
                            s.summary().dark_readings());
  }
};

TEST_F(DaemonSessionTest, SampleRotationPlanRunsToCompletionWithEveryReadingAndEvent) {
  Result<v1::Session> submitted = rig_.Submit(kRotationPlan);
  ASSERT_TRUE(submitted.ok()) << submitted.status().ToString();
  const std::string id = submitted->session_id();
  EXPECT_GT(submitted->summary().sample_readings(), 0u);
  GrpcOperator& op = Watch(id);

  // A follower of the readings stream sees every reading as it lands, then the stream closes.
  std::vector<v1::Reading> followed;
  grpc::Status follow_status;
  std::thread follower([&] {
    v1::StreamReadingsRequest request;
    request.set_session_id(id);
    request.set_follow(true);
    auto context = DaemonRig::Context(kAnalystToken, 60s);
    auto reader = rig_.data().StreamReadings(context.get(), request);
    v1::Reading r;
    while (reader->Read(&r)) followed.push_back(r);
    follow_status = reader->Finish();
  });

  const v1::Session done = rig_.WaitForState(id, v1::SESSION_STATE_COMPLETED, 60s);
  follower.join();
  ASSERT_EQ(done.state(), v1::SESSION_STATE_COMPLETED) << done.DebugString();
  EXPECT_EQ(done.progress().done_steps(), done.progress().total_steps());
  EXPECT_EQ(done.progress().done_samples(), done.summary().sample_readings());
  EXPECT_EQ(done.eta_s(), 0);

  // Readings: as many as planned, each sample divided by a reference and a dark of the session.
  const std::vector<v1::Reading> readings = Readings(id);
  ASSERT_EQ(static_cast<int>(readings.size()), PlannedReadings(done));
  std::map<std::int64_t, v1::ReadingKind> kind_of;
  for (const auto& r : readings) kind_of[r.id()] = r.kind();
  for (std::size_t i = 0; i < readings.size(); ++i) {
    const v1::Reading& r = readings[i];
    if (i > 0) {
      EXPECT_GT(r.id(), readings[i - 1].id());
    }
    EXPECT_EQ(r.session_id(), id);
    EXPECT_EQ(r.radiance_size(), static_cast<int>(r.grid().count()));
    if (r.kind() == v1::READING_KIND_SAMPLE) {
      EXPECT_EQ(kind_of[r.reference_id()], v1::READING_KIND_REFERENCE) << r.id();
      EXPECT_LT(r.reference_id(), r.id());
      EXPECT_EQ(kind_of[r.dark_id()], v1::READING_KIND_DARK) << r.id();
      EXPECT_FALSE(r.label().empty());
    }
  }
  // The follower got the same readings, in the same order, and its stream ended cleanly.
  EXPECT_TRUE(follow_status.ok()) << follow_status.error_message();
  ASSERT_EQ(followed.size(), readings.size());
  for (std::size_t i = 0; i < readings.size(); ++i) EXPECT_EQ(followed[i].id(), readings[i].id());
  // after_id resumes a broken stream where it stopped.
  {
    v1::StreamReadingsRequest request;
    request.set_session_id(id);
    request.set_after_id(readings[readings.size() / 2].id());
    request.add_kinds(v1::READING_KIND_SAMPLE);
    auto context = DaemonRig::Context(kAnalystToken);
    auto reader = rig_.data().StreamReadings(context.get(), request);
    v1::Reading r;
    std::size_t n = 0;
    while (reader->Read(&r)) {
      EXPECT_GT(r.id(), readings[readings.size() / 2].id());
      EXPECT_EQ(r.kind(), v1::READING_KIND_SAMPLE);
      ++n;
    }
    EXPECT_TRUE(reader->Finish().ok());
    std::size_t expected = 0;
    for (std::size_t i = readings.size() / 2 + 1; i < readings.size(); ++i) {
      expected += readings[i].kind() == v1::READING_KIND_SAMPLE ? 1 : 0;
    }
    EXPECT_EQ(n, expected);
  }

  // The compact listing (StreamReadingPoints): the same sample readings, in the same order, as
  // columns of ids, poses and isotropic directions.
  {
    v1::StreamReadingsRequest request;
    request.set_session_id(id);
    request.add_kinds(v1::READING_KIND_SAMPLE);
    auto context = DaemonRig::Context(kAnalystToken);
    auto reader = rig_.data().StreamReadingPoints(context.get(), request);
    v1::ReadingPoints points;
    std::vector<const v1::Reading*> samples;
    for (const auto& r : readings) {
      if (r.kind() == v1::READING_KIND_SAMPLE) samples.push_back(&r);
    }
    std::size_t k = 0;
    while (reader->Read(&points)) {
      ASSERT_EQ(points.theta_i_size(), points.ids_size());
      ASSERT_EQ(points.flagged_size(), points.ids_size());
      for (int j = 0; j < points.ids_size(); ++j, ++k) {
        ASSERT_LT(k, samples.size());
        const v1::Reading& r = *samples[k];
        EXPECT_EQ(points.ids(j), r.id());
        // Angles to the micro-degree (the nearest multiple of 1e-6°, so 59.999999999999993
        // becomes 60).
        constexpr double kMicro = 0.5e-6 + 1e-12;
        EXPECT_NEAR(points.alpha(j), r.pose().alpha(), kMicro);
        EXPECT_NEAR(points.beta(j), r.pose().beta(), kMicro);
        EXPECT_NEAR(points.delta(j), r.pose().delta(), kMicro);
        EXPECT_NEAR(points.theta_i(j), r.iso().theta_i(), kMicro);
        EXPECT_NEAR(points.theta_o(j), r.iso().theta_o(), kMicro);
        EXPECT_NEAR(points.phi(j), r.iso().phi(), kMicro);
        for (double v : {points.alpha(j), points.theta_i(j), points.theta_o(j), points.phi(j)}) {
          EXPECT_NEAR(v * 1e6, std::round(v * 1e6), 1e-6) << v << " is not a whole micro-degree";
        }
        EXPECT_EQ(points.flagged(j), r.flagged());
      }
    }
    EXPECT_TRUE(reader->Finish().ok());
    EXPECT_EQ(k, samples.size());
  }
  // Its errors name the method the client called, not StreamReadings whose request it shares.
  {
    v1::StreamReadingsRequest request;
    request.set_session_id(id);
    auto context = DaemonRig::Context("");
    auto reader = rig_.data().StreamReadingPoints(context.get(), request);
    v1::ReadingPoints points;
    EXPECT_FALSE(reader->Read(&points));
    const grpc::Status st = reader->Finish();
    EXPECT_EQ(st.error_code(), grpc::StatusCode::UNAUTHENTICATED);
    EXPECT_EQ(st.error_message().rfind("StreamReadingPoints: ", 0), 0u) << st.error_message();
  }

  // The watcher: a snapshot first, sequence numbers increasing, step completions with progress,
  // the prompts the plan needs, and the stream closed after the session completed.
  for (int i = 0; i < 100 && !op.finished(); ++i) std::this_thread::sleep_for(20ms);
  ASSERT_TRUE(op.finished());
  EXPECT_TRUE(op.stream_status().ok()) << op.stream_status().error_message();
  const std::vector<v1::SessionEvent> events = op.events();
  ASSERT_FALSE(events.empty());
  EXPECT_TRUE(events.front().has_snapshot());
  std::uint32_t last_done = 0;
  int completions = 0;
  for (std::size_t i = 1; i < events.size(); ++i) {
    EXPECT_GT(events[i].sequence(), events[i - 1].sequence());
    if (events[i].has_step_completed()) {
      ++completions;
      EXPECT_GE(events[i].step_completed().progress().done_steps(), last_done);
      last_done = events[i].step_completed().progress().done_steps();
    }
  }
  EXPECT_GT(completions, 0);
  EXPECT_EQ(last_done, done.progress().total_steps());
  ASSERT_TRUE(events.back().has_state_changed());
  EXPECT_EQ(events.back().state_changed().to(), v1::SESSION_STATE_COMPLETED);
  std::multiset<v1::PromptKind> kinds;
  for (const auto& p : op.prompts_answered()) kinds.insert(p.kind());
  EXPECT_EQ(kinds.count(v1::PROMPT_KIND_MOUNT_WHITE), 2u);  // one reference block per δ
  EXPECT_EQ(kinds.count(v1::PROMPT_KIND_CLOSE_SHUTTER), 2u);
  EXPECT_EQ(kinds.count(v1::PROMPT_KIND_MOUNT_SAMPLE), 2u);

  ExpectIntact(IdOf(done));
  // The audit log names the token's NAME with its role; no token appears in it or in the log.
  Result<std::vector<AuditRow>> audit = AuditRows(rig_.database());
  ASSERT_TRUE(audit.ok()) << audit.status().ToString();
  bool submitted_by_operator = false;
  for (const AuditRow& row : *audit) {
    submitted_by_operator |=
        row.action == "session.submit" && row.actor == kOperatorName && row.role == "operator";
    for (const std::string& text : {row.role, row.actor, row.action, row.detail}) {
      EXPECT_EQ(text.find(kOperatorToken), std::string::npos);
      EXPECT_EQ(text.find(kAnalystToken), std::string::npos);
    }
  }
  EXPECT_TRUE(submitted_by_operator);
  EXPECT_EQ(rig_.log().find(kOperatorToken), std::string::npos);
  EXPECT_EQ(rig_.log().find(kAnalystToken), std::string::npos);
}

TEST_F(DaemonSessionTest, SampleFixedPlanWaitsForEachPromptTheTestAnswers) {
  Result<v1::Session> submitted = rig_.Submit(kFixedPlan);
  ASSERT_TRUE(submitted.ok()) << submitted.status().ToString();
  const std::string id = submitted->session_id();
  EXPECT_EQ(submitted->summary().sample_readings(), 3u);

  // Nobody answers yet: the session waits for the operator with the first prompt pending.
  GrpcOperator& op = Watch(id, /*answering=*/false);
  v1::Session waiting = rig_.WaitForState(id, v1::SESSION_STATE_AWAITING_OPERATOR, 20s);
  ASSERT_EQ(waiting.state(), v1::SESSION_STATE_AWAITING_OPERATOR);
  ASSERT_TRUE(waiting.has_pending_prompt());
  // A wrong step index never confirms the pending prompt.
  {
    v1::AnswerPromptRequest request;
    request.set_session_id(id);
    request.set_step_index(waiting.pending_prompt().step_index() + 1);
    v1::AnswerPromptResponse response;
    grpc::Status st = rig_.control().AnswerPrompt(DaemonRig::Context().get(), request, &response);
    EXPECT_EQ(st.error_code(), grpc::StatusCode::FAILED_PRECONDITION) << st.error_message();
  }
  // Now the operator does the work.
  op.Stop();
  GrpcOperator& answering = Watch(id);
  const v1::Session done = rig_.WaitForState(id, v1::SESSION_STATE_COMPLETED, 40s);
  ASSERT_EQ(done.state(), v1::SESSION_STATE_COMPLETED) << done.DebugString();

  std::vector<v1::Prompt> relocations;
  for (const auto& p : answering.prompts_answered()) {
    if (p.kind() == v1::PROMPT_KIND_RELOCATE_LAMP_AND_DETECTOR) relocations.push_back(p);
  }
  ASSERT_EQ(relocations.size(), 3u);
  EXPECT_NE(relocations[1].text().find("30"), std::string::npos) << relocations[1].text();

  // Each sample reading carries its target's directions and label.
  const std::vector<v1::Reading> readings = Readings(id);
  ASSERT_EQ(static_cast<int>(readings.size()), PlannedReadings(done));
  struct Target {
    double ti, to, phi;
    const char* label;
  };
  const Target targets[] = {{0, 45, 0, "0/45"},
                            {30, 30, 180, "specular 30"},
                            {20, 50, 90, "side"}};  // φ is 0 where θi is 0 (geometry.md)
  std::size_t t = 0;
  for (const auto& r : readings) {
    if (r.kind() != v1::READING_KIND_SAMPLE) continue;
    ASSERT_LT(t, 3u);
    EXPECT_NEAR(r.iso().theta_i(), targets[t].ti, 1e-6);
    EXPECT_NEAR(r.iso().theta_o(), targets[t].to, 1e-6);
    EXPECT_NEAR(r.iso().phi(), targets[t].phi, 1e-6);
    EXPECT_NE(r.label().find(targets[t].label), std::string::npos) << r.label();
    ++t;
  }
  EXPECT_EQ(t, 3u);
  ExpectIntact(IdOf(done));
}

TEST_F(DaemonSessionTest, DeferredAndImmediatePauseThenResumeLoseAndRepeatNothing) {
  v1::Session s = SubmitAndWatch(kSlowPlan);
  const std::string id = s.session_id();
  const std::int64_t sid = IdOf(s);

  // Deferred: the step in progress finishes, then the session is paused and stays so.
  rig_.WaitFor(id, [](const v1::Session& x) {
    return x.progress().done_samples() >= 1 && x.state() == v1::SESSION_STATE_RUNNING;
  });
  v1::PauseSessionRequest pause;
  pause.set_session_id(id);
  pause.set_mode(v1::PAUSE_MODE_DEFERRED);
  v1::PauseSessionResponse paused;
  grpc::Status st = rig_.control().PauseSession(DaemonRig::Context().get(), pause, &paused);
  ASSERT_TRUE(st.ok()) << st.error_message();
  EXPECT_TRUE(paused.session().state() == v1::SESSION_STATE_PAUSING ||
              paused.session().state() == v1::SESSION_STATE_PAUSED)
      << v1::SessionState_Name(paused.session().state());
  s = rig_.WaitForState(id, v1::SESSION_STATE_PAUSED);
  ASSERT_EQ(s.state(), v1::SESSION_STATE_PAUSED);
  const auto at_pause = s.progress().done_steps();
  std::this_thread::sleep_for(400ms);
  EXPECT_EQ(rig_.Get(id)->progress().done_steps(), at_pause);
  ExpectIntact(sid);
  // Resuming a paused session runs it; resuming a running one is refused with the state.
  v1::ResumeSessionRequest resume;
  resume.set_session_id(id);
  v1::ResumeSessionResponse resumed;
  st = rig_.control().ResumeSession(DaemonRig::Context().get(), resume, &resumed);
  ASSERT_TRUE(st.ok()) << st.error_message();
  EXPECT_EQ(resumed.session().state(), v1::SESSION_STATE_RUNNING);
  st = rig_.control().ResumeSession(DaemonRig::Context().get(), resume, &resumed);
  EXPECT_EQ(st.error_code(), grpc::StatusCode::FAILED_PRECONDITION) << st.error_message();
  EXPECT_NE(st.error_message().find("running"), std::string::npos) << st.error_message();

  // Immediate: caught inside a sample reading, the step is cancelled and not marked done.
  Result<std::vector<DbStep>> steps = SessionSteps(rig_.database(), sid);
  ASSERT_TRUE(steps.ok()) << steps.status().ToString();
  auto is_sample = [&](int i) {
    return i >= 0 && i < static_cast<int>(steps->size()) &&
           (*steps)[static_cast<std::size_t>(i)].kind == "sample";
  };
  // The pause must land inside a reading: on a loaded machine the reading may end first, then
  // the pause catches the move after it; resume and try the next reading.
  int cancelled = -1;
  pause.set_mode(v1::PAUSE_MODE_IMMEDIATE);
  for (int attempt = 0; attempt < 4 && !is_sample(cancelled); ++attempt) {
    if (attempt > 0) {
      st = rig_.control().ResumeSession(DaemonRig::Context().get(), resume, &resumed);
      ASSERT_TRUE(st.ok()) << st.error_message();
    }
    const auto done_before = rig_.Get(id)->progress().done_steps();
    s = rig_.WaitFor(id, [&](const v1::Session& x) {
      return x.state() == v1::SESSION_STATE_RUNNING && is_sample(x.current_step()) &&
             x.progress().done_steps() > done_before;
    });
    ASSERT_TRUE(is_sample(s.current_step())) << s.DebugString();
    std::this_thread::sleep_for(40ms);  // inside the measurement (a reading takes ~180 ms)
    st = rig_.control().PauseSession(DaemonRig::Context().get(), pause, &paused);
    ASSERT_TRUE(st.ok()) << st.error_message();
    ASSERT_EQ(paused.session().state(), v1::SESSION_STATE_PAUSED);
    cancelled = paused.session().current_step();
  }
  ASSERT_TRUE(is_sample(cancelled)) << cancelled;
  // Longer than the reading would have taken: nothing was written for that step.
  std::this_thread::sleep_for(500ms);
  steps = SessionSteps(rig_.database(), sid);
  ASSERT_TRUE(steps.ok());
  EXPECT_EQ((*steps)[static_cast<std::size_t>(cancelled)].state, "pending");
  for (const auto& r : Readings(id)) EXPECT_NE(r.step_index(), cancelled);
  ExpectIntact(sid);

  st = rig_.control().ResumeSession(DaemonRig::Context().get(), resume, &resumed);
  ASSERT_TRUE(st.ok()) << st.error_message();
  const v1::Session done = rig_.WaitForState(id, v1::SESSION_STATE_COMPLETED, 40s);
  ASSERT_EQ(done.state(), v1::SESSION_STATE_COMPLETED);
  const std::vector<v1::Reading> readings = Readings(id);
  EXPECT_EQ(static_cast<int>(readings.size()), PlannedReadings(done));
  EXPECT_EQ(std::count_if(readings.begin(), readings.end(),
                          [&](const v1::Reading& r) { return r.step_index() == cancelled; }),
            1);
  ExpectIntact(sid);
}

TEST_F(DaemonSessionTest, AbortKeepsTheReadingsAndIsFinal) {
  const v1::Session s = SubmitAndWatch(kRotationPlan);
  const std::string id = s.session_id();
  rig_.WaitFor(id, [](const v1::Session& x) { return x.progress().done_samples() >= 2; });
  v1::AbortSessionRequest abort;
  abort.set_session_id(id);
  abort.set_reason("lamp flickers");
  v1::AbortSessionResponse aborted;
  grpc::Status st = rig_.control().AbortSession(DaemonRig::Context().get(), abort, &aborted);
  ASSERT_TRUE(st.ok()) << st.error_message();
  EXPECT_EQ(aborted.session().state(), v1::SESSION_STATE_ABORTED);
  EXPECT_NE(aborted.session().end_reason().find("lamp flickers"), std::string::npos);

  std::this_thread::sleep_for(300ms);  // the run winds down; nothing more is written
  const std::vector<v1::Reading> readings = Readings(id);
  EXPECT_GE(readings.size(), 2u);
  const v1::Session after = *rig_.Get(id);
  EXPECT_EQ(after.state(), v1::SESSION_STATE_ABORTED);
  EXPECT_LT(after.progress().done_steps(), after.progress().total_steps());
  ExpectIntact(IdOf(s));

  v1::ResumeSessionRequest resume;
  resume.set_session_id(id);
  v1::ResumeSessionResponse resumed;
  st = rig_.control().ResumeSession(DaemonRig::Context().get(), resume, &resumed);
  EXPECT_EQ(st.error_code(), grpc::StatusCode::FAILED_PRECONDITION) << st.error_message();
  // The rig is free again: the next session runs to the end.
  const v1::Session next = SubmitAndWatch(kTinyPlan);
  EXPECT_EQ(rig_.WaitForState(next.session_id(), v1::SESSION_STATE_COMPLETED).state(),
            v1::SESSION_STATE_COMPLETED);
}

TEST_F(DaemonSessionTest, DeviceFaultPausesTheSessionWithTheFaultAndResumeCompletes) {
  // The simulated meter reports quality code 14 for the next two measurements: with two
  // attempts per step, the step fails for good and the session pauses.
  sim::SerialFaults faults;
  faults.quality_code = 14;
  faults.quality_count = 2;
  ASSERT_TRUE(rig_.sim_control().SetSerialFaults(faults).ok());
  const v1::Session s = SubmitAndWatch(kTinyPlan);
  const std::string id = s.session_id();
  GrpcOperator& op = *operators_.back();

  v1::Session paused = rig_.WaitForState(id, v1::SESSION_STATE_PAUSED);
  ASSERT_EQ(paused.state(), v1::SESSION_STATE_PAUSED) << paused.DebugString();
  ASSERT_TRUE(paused.has_last_fault());
  EXPECT_EQ(paused.last_fault().device_code(), 14);
  EXPECT_FALSE(paused.last_fault().will_retry());
  EXPECT_EQ(paused.last_quality_code(), 14);
  Result<DbSessionCounts> db = CountSession(rig_.database(), IdOf(s));
  ASSERT_TRUE(db.ok());
  EXPECT_EQ(db->state, "paused");
  EXPECT_NE(db->state_reason.find("14"), std::string::npos) << db->state_reason;
  ExpectIntact(IdOf(s));

  v1::ResumeSessionRequest resume;
  resume.set_session_id(id);
  v1::ResumeSessionResponse resumed;
  grpc::Status st = rig_.control().ResumeSession(DaemonRig::Context().get(), resume, &resumed);
  ASSERT_TRUE(st.ok()) << st.error_message();
  const v1::Session done = rig_.WaitForState(id, v1::SESSION_STATE_COMPLETED);
  ASSERT_EQ(done.state(), v1::SESSION_STATE_COMPLETED);
  EXPECT_EQ(static_cast<int>(Readings(id).size()), PlannedReadings(done));
  ExpectIntact(IdOf(s));
  // The watcher saw both failed attempts as faults: the first to be retried, the second not.
  std::vector<bool> will_retry;
  for (const auto& e : op.events()) {
    if (e.has_fault()) will_retry.push_back(e.fault().will_retry());
  }
  EXPECT_EQ(will_retry, (std::vector<bool>{true, false}));
}

TEST_F(DaemonSessionTest, KillNineMidSessionRestartResumeLosesAndDuplicatesNothing) {
  const v1::Session s = SubmitAndWatch(kRotationPlan);
  const std::string id = s.session_id();
  const std::int64_t sid = IdOf(s);
  rig_.WaitFor(id, [](const v1::Session& x) {
    return x.progress().done_samples() >= 3 && x.state() == v1::SESSION_STATE_RUNNING;
  });
  operators_.back()->Stop();
  rig_.KillDaemon();  // SIGKILL: no shutdown code runs

  Result<DbSessionCounts> before = CountSession(rig_.database(), sid);
  ASSERT_TRUE(before.ok()) << before.status().ToString();
  EXPECT_NE(before->state, "completed");
  EXPECT_GT(before->readings, 0);
  ExpectIntact(sid);

  Status restarted = rig_.StartDaemon();
  ASSERT_TRUE(restarted.ok()) << restarted.ToString();
  v1::Session recovered = *rig_.Get(id);
  EXPECT_EQ(recovered.state(), v1::SESSION_STATE_PAUSED);
  // It says it was recovered and why it is paused, in the API as in the database.
  EXPECT_NE(recovered.state_reason().find("recovered after a restart"), std::string::npos)
      << recovered.state_reason();
  EXPECT_NE(recovered.state_reason().find("resume it to go on"), std::string::npos)
      << recovered.state_reason();
  Result<DbSessionCounts> parked = CountSession(rig_.database(), sid);
  ASSERT_TRUE(parked.ok());
  EXPECT_NE(parked->state_reason.find("recovered after a restart"), std::string::npos)
      << parked->state_reason;
  EXPECT_EQ(parked->readings, before->readings);

  Watch(id);
  v1::ResumeSessionRequest resume;
  resume.set_session_id(id);
  v1::ResumeSessionResponse resumed;
  grpc::Status st = rig_.control().ResumeSession(DaemonRig::Context().get(), resume, &resumed);
  ASSERT_TRUE(st.ok()) << st.error_message();
  const v1::Session done = rig_.WaitForState(id, v1::SESSION_STATE_COMPLETED, 60s);
  ASSERT_EQ(done.state(), v1::SESSION_STATE_COMPLETED) << done.DebugString();

  Result<DbSessionCounts> after = CountSession(rig_.database(), sid);
  ASSERT_TRUE(after.ok());
  EXPECT_EQ(after->steps_pending, 0);
  EXPECT_EQ(after->steps_done, after->total_steps);
  EXPECT_EQ(after->readings, PlannedReadings(done));
  EXPECT_EQ(after->duplicate_readings, 0);
  ExpectIntact(sid);
}

TEST_F(DaemonSessionTest, SigtermPausesTheRunningSessionAndExitsZero) {
  const v1::Session s = SubmitAndWatch(kSlowPlan);
  const std::string id = s.session_id();
  rig_.WaitFor(id, [](const v1::Session& x) {
    return x.progress().done_samples() >= 1 && x.state() == v1::SESSION_STATE_RUNNING;
  });
  Result<int> code = rig_.StopDaemon();
  ASSERT_TRUE(code.ok()) << code.status().ToString();
  EXPECT_EQ(*code, 0);
  Result<DbSessionCounts> db = CountSession(rig_.database(), IdOf(s));
  ASSERT_TRUE(db.ok());
  EXPECT_EQ(db->state, "paused") << db->state_reason;
  EXPECT_LT(db->steps_done, db->total_steps);
  ExpectIntact(IdOf(s));
  // Back up, it stays paused until the operator resumes it.
  Status restarted = rig_.StartDaemon();
  ASSERT_TRUE(restarted.ok()) << restarted.ToString();
  EXPECT_EQ(rig_.Get(id)->state(), v1::SESSION_STATE_PAUSED);
}

}  // namespace
}  // namespace brdf::testing
