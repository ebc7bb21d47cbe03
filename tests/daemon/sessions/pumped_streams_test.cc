// The long-lived streams hold no thread while they wait (issue 40): WatchSession and following
// StreamReadings run on brdfd's stream pump (daemon/api/stream_pump.h, gRPC's callback API), so
// sixty idle ones do not add sixty threads to the daemon (on gRPC's synchronous pool each held
// one), and each still gets every event and every reading as the session records them.
#include <gtest/gtest.h>

#include <chrono>
#include <fstream>
#include <iostream>
#include <string>
#include <thread>
#include <vector>

#include "tests/daemon/sessions/rig_test.h"
#include "tests/support/plan_fixtures.h"

namespace brdf::testing {
namespace {

using namespace std::chrono_literals;

// brdfd's threads now (/proc/PID/status), -1 when it cannot be read.
int ThreadsOf(pid_t pid) {
  std::ifstream status("/proc/" + std::to_string(pid) + "/status");
  std::string key;
  while (status >> key) {
    if (key == "Threads:") {
      int n = -1;
      status >> n;
      return n;
    }
    std::getline(status, key);
  }
  return -1;
}

// One open stream read on a client thread of its own until it ends.
template <class Message>
struct Held {
  std::unique_ptr<grpc::ClientContext> context;
  std::unique_ptr<grpc::ClientReader<Message>> reader;
  std::vector<Message> got;
  grpc::Status status;
  std::thread reading;
  void ReadToEnd() {
    reading = std::thread([this] {
      Message m;
      while (reader->Read(&m)) got.push_back(m);
      status = reader->Finish();
    });
  }
};

class PumpedStreamsTest : public SessionRigTest {};

TEST_F(PumpedStreamsTest, IdleWatchesAndFollowersHoldNoThreadYetGetEveryEventAndReading) {
  constexpr int kWatches = 40;
  constexpr int kFollowers = 20;  // with the watches, within max_streams_per_token (64)
  Result<v1::Session> queued = rig_.Submit(plans::SmallRotation(), /*start_now=*/false);
  ASSERT_TRUE(queued.ok()) << queued.status().ToString();
  const std::string id = queued->session_id();
  const pid_t pid = rig_.daemon()->pid();
  const int before = ThreadsOf(pid);
  ASSERT_GT(before, 0);

  std::vector<std::unique_ptr<Held<v1::SessionEvent>>> watches;
  for (int i = 0; i < kWatches; ++i) {
    auto w = std::make_unique<Held<v1::SessionEvent>>();
    w->context = DaemonRig::Context(kAnalystToken, 120s);
    v1::WatchSessionRequest request;
    request.set_session_id(id);
    w->reader = rig_.control().WatchSession(w->context.get(), request);
    v1::SessionEvent snapshot;
    ASSERT_TRUE(w->reader->Read(&snapshot)) << "watch " << i << ": no snapshot";
    w->got.push_back(snapshot);
    watches.push_back(std::move(w));
  }
  std::vector<std::unique_ptr<Held<v1::Reading>>> followers;
  for (int i = 0; i < kFollowers; ++i) {
    auto f = std::make_unique<Held<v1::Reading>>();
    f->context = DaemonRig::Context(kAnalystToken, 120s);
    v1::StreamReadingsRequest request;
    request.set_session_id(id);
    request.set_follow(true);
    f->reader = rig_.data().StreamReadings(f->context.get(), request);
    followers.push_back(std::move(f));
  }
  std::this_thread::sleep_for(1500ms);  // every stream opened and waiting (nothing recorded yet)
  const int waiting = ThreadsOf(pid);
  std::cout << kWatches << " watches and " << kFollowers << " followers waiting: brdfd threads "
            << before << " -> " << waiting << "\n";
  // On the synchronous pool: at least one thread per stream (+60). The pump's threads and
  // gRPC's own (callback executor, pollers) are a few, whatever the number of streams.
  EXPECT_LT(waiting - before, 16) << "threads " << before << " -> " << waiting;

  for (auto& w : watches) w->ReadToEnd();
  for (auto& f : followers) f->ReadToEnd();
  Watch(id);  // the operator, answering the session's prompts
  auto start = DaemonRig::Context();
  v1::StartSessionRequest start_request;
  start_request.set_session_id(id);
  v1::StartSessionResponse started;
  ASSERT_TRUE(rig_.control().StartSession(start.get(), start_request, &started).ok());
  const v1::Session done = rig_.WaitForState(id, v1::SESSION_STATE_COMPLETED, 90s);
  ASSERT_EQ(done.state(), v1::SESSION_STATE_COMPLETED) << done.DebugString();
  const int planned =
      static_cast<int>(done.summary().sample_readings() + done.summary().reference_readings() +
                       done.summary().dark_readings());

  // Each watch got the whole session, ending with its completion; each follower every reading
  // once, in id order; all streams ended OK when the session did.
  for (auto& w : watches) {
    w->reading.join();
    EXPECT_TRUE(w->status.ok()) << w->status.error_message();
    ASSERT_GT(w->got.size(), 2u);
    EXPECT_EQ(w->got.back().state_changed().to(), v1::SESSION_STATE_COMPLETED)
        << w->got.back().DebugString();
    EXPECT_EQ(w->got.size(), watches.front()->got.size());
  }
  for (auto& f : followers) {
    f->reading.join();
    EXPECT_TRUE(f->status.ok()) << f->status.error_message();
    std::string ids;
    for (const v1::Reading& r : f->got) ids += " " + std::to_string(r.id());
    ASSERT_EQ(static_cast<int>(f->got.size()), planned) << "ids:" << ids;
    for (std::size_t i = 1; i < f->got.size(); ++i) {
      EXPECT_GT(f->got[i].id(), f->got[i - 1].id());
    }
  }
}

}  // namespace
}  // namespace brdf::testing
