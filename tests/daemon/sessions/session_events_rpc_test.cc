// Control.ListSessionEvents on brdfd: a session's durable history of states (the store's
// session_events, storage/schema.md) served over gRPC, with brdfd and brdf-simulated devices as
// processes.
#include <gtest/gtest.h>

#include <chrono>
#include <string>
#include <vector>

#include "google/protobuf/util/time_util.h"
#include "tests/daemon/sessions/rig_test.h"
#include "tests/support/plan_fixtures.h"

namespace brdf::testing {
namespace {

using namespace std::chrono_literals;
using google::protobuf::util::TimeUtil;

class SessionEventsRpcTest : public SessionRigTest {
 protected:
  grpc::Status List(const std::string& id, v1::ListSessionEventsResponse* out,
                    const std::string& token = kOperatorToken) {
    v1::ListSessionEventsRequest request;
    request.set_session_id(id);
    return rig_.control().ListSessionEvents(DaemonRig::Context(token).get(), request, out);
  }
};

std::string Names(const std::vector<v1::SessionState>& states) {
  std::string out;
  for (v1::SessionState s : states) out += v1::SessionState_Name(s) + " ";
  return out;
}

TEST_F(SessionEventsRpcTest, PauseResumeCompleteIsTheHistoryInOrderWithReasons) {
  const auto started = TimeUtil::GetCurrentTime();
  Result<v1::Session> submitted =
      rig_.Submit(plans::SlowRotation(/*alpha_stop=*/10, /*beta_step=*/45, /*averages=*/10));
  ASSERT_TRUE(submitted.ok()) << submitted.status().ToString();
  const std::string id = submitted->session_id();
  Watch(id);

  rig_.WaitFor(id, [](const v1::Session& x) {
    return x.progress().done_samples() >= 1 && x.state() == v1::SESSION_STATE_RUNNING;
  });
  v1::PauseSessionRequest pause;
  pause.set_session_id(id);
  pause.set_mode(v1::PAUSE_MODE_DEFERRED);
  v1::PauseSessionResponse paused;
  grpc::Status st = rig_.control().PauseSession(DaemonRig::Context().get(), pause, &paused);
  ASSERT_TRUE(st.ok()) << st.error_message();
  const v1::Session at_pause = rig_.WaitForState(id, v1::SESSION_STATE_PAUSED);
  ASSERT_EQ(at_pause.state(), v1::SESSION_STATE_PAUSED);
  ASSERT_FALSE(at_pause.state_reason().empty());

  v1::ResumeSessionRequest resume;
  resume.set_session_id(id);
  v1::ResumeSessionResponse resumed;
  st = rig_.control().ResumeSession(DaemonRig::Context().get(), resume, &resumed);
  ASSERT_TRUE(st.ok()) << st.error_message();
  const v1::Session done = rig_.WaitForState(id, v1::SESSION_STATE_COMPLETED, 60s);
  ASSERT_EQ(done.state(), v1::SESSION_STATE_COMPLETED);
  const auto finished = TimeUtil::GetCurrentTime();

  v1::ListSessionEventsResponse history;
  st = List(id, &history);
  ASSERT_TRUE(st.ok()) << st.error_message();
  ASSERT_GE(history.events_size(), 5);

  // Ids increase, times do not go back and lie within the test's span (the store's clock).
  for (int i = 0; i < history.events_size(); ++i) {
    const v1::SessionStateEvent& e = history.events(i);
    EXPECT_GE(e.at(), started - TimeUtil::SecondsToDuration(1)) << e.DebugString();
    EXPECT_LE(e.at(), finished + TimeUtil::SecondsToDuration(1)) << e.DebugString();
    if (i > 0) {
      EXPECT_GT(e.id(), history.events(i - 1).id());
      EXPECT_GE(e.at(), history.events(i - 1).at());
    }
  }

  // The states in order, leaving out the prompts' AWAITING_OPERATOR (the plan mounts the white
  // and the sample) and a repeat of the same state (a reason changed). PAUSING may be skipped
  // when the step in progress ended before the pause was asked.
  std::vector<v1::SessionState> states;
  for (const v1::SessionStateEvent& e : history.events()) {
    if (e.state() == v1::SESSION_STATE_AWAITING_OPERATOR) continue;
    if (!states.empty() && states.back() == e.state()) continue;
    states.push_back(e.state());
  }
  std::vector<v1::SessionState> want = {v1::SESSION_STATE_QUEUED,  v1::SESSION_STATE_RUNNING,
                                        v1::SESSION_STATE_PAUSING, v1::SESSION_STATE_PAUSED,
                                        v1::SESSION_STATE_RUNNING, v1::SESSION_STATE_COMPLETED};
  if (paused.session().state() == v1::SESSION_STATE_PAUSED) want.erase(want.begin() + 2);
  EXPECT_EQ(Names(states), Names(want));

  EXPECT_EQ(history.events(0).state(), v1::SESSION_STATE_QUEUED);
  EXPECT_EQ(TimeUtil::TimestampToMilliseconds(history.events(0).at()),
            TimeUtil::TimestampToMilliseconds(submitted->created_at()));
  // The pause's reason is the one the session showed while paused; the last event is the end.
  bool saw_pause_reason = false;
  for (const v1::SessionStateEvent& e : history.events()) {
    if (e.state() == v1::SESSION_STATE_PAUSED && e.reason() == at_pause.state_reason()) {
      saw_pause_reason = true;
    }
  }
  EXPECT_TRUE(saw_pause_reason) << history.DebugString() << "\nwant reason "
                                << at_pause.state_reason();
  const v1::SessionStateEvent& last = history.events(history.events_size() - 1);
  EXPECT_EQ(last.state(), v1::SESSION_STATE_COMPLETED);
  EXPECT_EQ(last.reason(), done.state_reason());

  // An analyst reads the same history.
  v1::ListSessionEventsResponse as_analyst;
  st = List(id, &as_analyst, kAnalystToken);
  ASSERT_TRUE(st.ok()) << st.error_message();
  EXPECT_EQ(as_analyst.SerializeAsString(), history.SerializeAsString());
}

TEST_F(SessionEventsRpcTest, UnknownOrMalformedSessionAndNoTokenAreRefused) {
  v1::ListSessionEventsResponse out;
  grpc::Status st = List("987654", &out);
  EXPECT_EQ(st.error_code(), grpc::StatusCode::NOT_FOUND) << st.error_message();
  EXPECT_NE(st.error_message().find("987654"), std::string::npos) << st.error_message();
  // Names the session, not where the daemon keeps it.
  EXPECT_EQ(st.error_message().find(rig_.dir().path().string()), std::string::npos)
      << st.error_message();
  EXPECT_EQ(st.error_message().find(".db"), std::string::npos) << st.error_message();
  EXPECT_EQ(out.events_size(), 0);

  st = List("not-a-session", &out);
  EXPECT_EQ(st.error_code(), grpc::StatusCode::INVALID_ARGUMENT) << st.error_message();
  EXPECT_NE(st.error_message().find("session_id"), std::string::npos) << st.error_message();

  st = List("987654", &out, /*token=*/"");
  EXPECT_EQ(st.error_code(), grpc::StatusCode::UNAUTHENTICATED) << st.error_message();

  // A queued session that never ran has its one event.
  Result<v1::Session> queued = rig_.Submit(plans::OnePose(), /*start_now=*/false);
  ASSERT_TRUE(queued.ok()) << queued.status().ToString();
  st = List(queued->session_id(), &out, kAnalystToken);
  ASSERT_TRUE(st.ok()) << st.error_message();
  ASSERT_EQ(out.events_size(), 1) << out.DebugString();
  EXPECT_EQ(out.events(0).state(), v1::SESSION_STATE_QUEUED);
}

}  // namespace
}  // namespace brdf::testing
