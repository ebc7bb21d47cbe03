// The control plane under analyst load (ctest label "load"; issue 20, the smaller version of
// bench/daemon/control_plane.sh): while a session records, 400 analyst streams are open
// (WatchSession read, StreamReadings following, InterpolateBatch and Export never read) and two
// clients call Interpolate; the operator's PauseSession and ResumeSession, GetRigStatus and the
// health service's Check must all answer, each within a few seconds, and none may fail. Before
// the control plane had threads of its own, such streams took every thread of gRPC's pool (256)
// and these calls failed with "Server Threadpool Exhausted" (as main's brdfd did here: at 300
// streams some of them still finished in time, at 400 GetRigStatus, Health and Pause failed).
#include <gtest/gtest.h>
#include <sys/utsname.h>

#include <algorithm>
#include <atomic>
#include <chrono>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>
#include <thread>
#include <vector>

#include "grpc/health/v1/health.grpc.pb.h"
#include "tests/support/daemon/test_rig.h"
#include "tests/support/plan_fixtures.h"

namespace brdf::testing {
namespace {

using namespace std::chrono_literals;

constexpr int kStreams = 400;
constexpr auto kAnswerWithin = 5s;

const std::string kLongPlan = PlanFixture("control plane under load")
                                  .SampleRotation({30, 30, 10}, {0, 60, 5}, 10)
                                  .Measurement(100, 1)
                                  .Retry(3, 0);

// Each thread of process `pid` as /proc shows it: its name (comm), nice value and the slice the
// scheduler gives it (ns; -1 when /proc does not show it).
struct ThreadNice {
  std::string name;
  int nice = 0;
  long long slice_ns = -1;
};

// The slice of a task as /proc/PID/task/TID/sched shows it ("se.slice : N"), or -1.
long long SliceNs(const std::filesystem::path& task) {
  std::ifstream sched(task / "sched");
  for (std::string line; std::getline(sched, line);) {
    if (line.rfind("se.slice", 0) == 0) return std::stoll(line.substr(line.find(':') + 1));
  }
  return -1;
}

// Linux 6.12 or later: a thread's slice may be asked for (sched_setattr's sched_runtime).
bool KernelTakesSlices() {
  utsname u{};
  if (::uname(&u) != 0) return false;
  int major = 0, minor = 0;
  if (std::sscanf(u.release, "%d.%d", &major, &minor) != 2) return false;
  return major > 6 || (major == 6 && minor >= 12);
}

std::vector<ThreadNice> Threads(pid_t pid) {
  std::vector<ThreadNice> threads;
  const std::filesystem::path tasks = "/proc/" + std::to_string(pid) + "/task";
  std::error_code error;
  for (const auto& task : std::filesystem::directory_iterator(tasks, error)) {
    std::ifstream comm(task.path() / "comm"), stat(task.path() / "stat");
    ThreadNice t;
    std::getline(comm, t.name);
    std::string line;
    std::getline(stat, line);
    // A thread that ended between the listing and the reading has no stat: not counted.
    const std::size_t name_end = line.rfind(')');
    if (name_end == std::string::npos || name_end + 2 > line.size()) continue;
    // Fields after the name's closing parenthesis: state is field 3, nice field 19.
    std::istringstream rest(line.substr(name_end + 2));
    std::string field;
    for (int i = 3; i <= 19 && rest >> field; ++i) {
      if (i == 19) t.nice = std::stoi(field);
    }
    t.slice_ns = SliceNs(task.path());
    threads.push_back(t);
  }
  return threads;
}

// The median of `n` GetRigStatus calls, ms (every call must succeed).
double MedianRigStatusMs(DaemonRig& rig, int n) {
  std::vector<double> ms;
  for (int i = 0; i < n; ++i) {
    const auto begin = std::chrono::steady_clock::now();
    v1::RigStatus status;
    const grpc::Status s =
        rig.control().GetRigStatus(DaemonRig::Context(kOperatorToken, 10s).get(), {}, &status);
    EXPECT_TRUE(s.ok()) << s.error_code() << " " << s.error_message();
    ms.push_back(std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - begin)
                     .count());
    std::this_thread::sleep_for(2ms);
  }
  std::sort(ms.begin(), ms.end());
  return ms[ms.size() / 2];
}

// A stream held open by the test: its reader and context (cancelled at the end).
struct Held {
  std::unique_ptr<grpc::ClientContext> context;
  std::unique_ptr<grpc::ClientReaderInterface<v1::SessionEvent>> watch;
  std::unique_ptr<grpc::ClientReaderInterface<v1::Reading>> readings;
  std::unique_ptr<grpc::ClientReaderInterface<v1::InterpolateBatchChunk>> batch;
  std::unique_ptr<grpc::ClientReaderInterface<v1::ExportChunk>> exported;
};

TEST(ControlPlaneLoadTest, OperatorCallsAnswerWhile400AnalystStreamsAreOpen) {
  DaemonRig rig;
  Status st = rig.StartSim();
  ASSERT_TRUE(st.ok()) << st.ToString();
  std::string toml = DaemonConfigToml(rig.sim(), rig.database());
  const std::string listen = "listen = \"127.0.0.1:0\"\n";
  toml.insert(toml.find(listen) + listen.size(), "max_streams_per_token = 450\n");
  st = rig.StartDaemon(toml);
  ASSERT_TRUE(st.ok()) << st.ToString();
  Result<v1::Session> submitted = rig.Submit(kLongPlan);
  ASSERT_TRUE(submitted.ok()) << submitted.status().ToString();
  const std::string id = submitted->session_id();
  GrpcOperator op(rig, id);
  const v1::Session recording = rig.WaitFor(
      id, [](const v1::Session& s) { return s.progress().done_samples() >= 2; }, 45s);
  ASSERT_GE(recording.progress().done_samples(), 2u) << rig.log();
  (void)MedianRigStatusMs(rig, 20);  // warm-up
  const double idle_ms = MedianRigStatusMs(rig, 40);

  // Two followers that read: under the load they get every reading of the session, in order, as
  // the fan-out hands them out (api/stream_readings_fanout.h), until the session ends.
  std::vector<std::vector<std::int64_t>> followed(2);
  std::vector<std::thread> followers;
  struct JoinFollowers {
    std::vector<std::thread>& threads;
    ~JoinFollowers() {
      for (std::thread& t : threads) {
        if (t.joinable()) t.join();
      }
    }
  } join_followers{followers};
  for (std::vector<std::int64_t>& ids : followed) {
    followers.emplace_back([&rig, &id, &ids] {
      v1::StreamReadingsRequest r;
      r.set_session_id(id);
      r.set_follow(true);
      auto context = DaemonRig::Context(kAnalystToken, 120s);
      auto stream = rig.data().StreamReadings(context.get(), r);
      v1::Reading reading;
      while (stream->Read(&reading)) ids.push_back(reading.id());
      const grpc::Status ended = stream->Finish();
      EXPECT_TRUE(ended.ok()) << ended.error_code() << " " << ended.error_message();
    });
  }

  // The analysts' streams, over 8 connections of their own.
  std::vector<std::shared_ptr<grpc::Channel>> channels;
  for (int c = 0; c < 8; ++c) {
    grpc::ChannelArguments args;
    args.SetInt("brdf.test.connection", c);
    channels.push_back(grpc::CreateCustomChannel(rig.daemon()->address(),
                                                 grpc::InsecureChannelCredentials(), args));
  }
  std::vector<Held> held;
  int snapshots = 0;
  for (int i = 0; i < kStreams; ++i) {
    const auto& channel = channels[static_cast<std::size_t>(i) % channels.size()];
    Held h;
    h.context = DaemonRig::Context(kAnalystToken, 120s);
    switch (i % 10) {
      case 0:
      case 1:
      case 2:
      case 3: {  // WatchSession, its snapshot read
        v1::WatchSessionRequest r;
        r.set_session_id(id);
        h.watch = v1::Control::NewStub(channel)->WatchSession(h.context.get(), r);
        v1::SessionEvent first;
        if (h.watch->Read(&first)) ++snapshots;
        break;
      }
      case 4:
      case 5:
      case 6: {  // StreamReadings following the session, never read
        v1::StreamReadingsRequest r;
        r.set_session_id(id);
        r.set_follow(true);
        h.readings = v1::Data::NewStub(channel)->StreamReadings(h.context.get(), r);
        break;
      }
      case 7:
      case 8: {  // InterpolateBatch of 2,000 directions, never read
        v1::InterpolateBatchRequest r;
        r.set_session_id(id);
        for (int d = 0; d < 2000; ++d) {
          v1::IsoDirection* at = r.add_directions()->mutable_iso();
          at->set_theta_i(30);
          at->set_theta_o(10 + d % 60);
          at->set_phi(d % 180);
        }
        h.batch = v1::Interpolation::NewStub(channel)->InterpolateBatch(h.context.get(), r);
        break;
      }
      default: {  // Export, never read
        v1::ExportRequest r;
        r.set_session_id(id);
        r.set_format(v1::EXPORT_FORMAT_READINGS_CSV);
        h.exported = v1::Data::NewStub(channel)->Export(h.context.get(), r);
        break;
      }
    }
    held.push_back(std::move(h));
  }
  EXPECT_EQ(snapshots, kStreams * 4 / 10) << "every watcher got its snapshot";

  // Two Interpolate clients meanwhile.
  std::atomic<bool> stop{false};
  std::atomic<int> interpolated{0};
  std::vector<std::thread> clients;
  // However the test ends (a failed ASSERT returns early), the clients stop and are joined: a
  // joinable thread left behind would abort the whole program without the failure's message.
  struct JoinClients {
    std::atomic<bool>& stop;
    std::vector<std::thread>& threads;
    ~JoinClients() {
      stop = true;
      for (std::thread& t : threads) {
        if (t.joinable()) t.join();
      }
    }
  } join_clients{stop, clients};
  for (int c = 0; c < 2; ++c) {
    clients.emplace_back([&] {
      auto stub = v1::Interpolation::NewStub(rig.channel());
      while (!stop) {
        v1::InterpolateRequest r;
        r.set_session_id(id);
        v1::IsoDirection* at = r.mutable_direction()->mutable_iso();
        at->set_theta_i(30);
        at->set_theta_o(30);
        at->set_phi(10);
        v1::InterpolateResponse answer;
        if (stub->Interpolate(DaemonRig::Context(kAnalystToken).get(), r, &answer).ok()) {
          ++interpolated;
        }
      }
    });
  }
  std::this_thread::sleep_for(1s);

  auto within = [](std::chrono::steady_clock::time_point begin) {
    return std::chrono::steady_clock::now() - begin < kAnswerWithin;
  };
  auto health = grpc::health::v1::Health::NewStub(rig.channel());
  for (int round = 0; round < 3; ++round) {
    auto begin = std::chrono::steady_clock::now();
    v1::RigStatus status;
    grpc::Status s =
        rig.control().GetRigStatus(DaemonRig::Context(kOperatorToken, 10s).get(), {}, &status);
    EXPECT_TRUE(s.ok()) << s.error_code() << " " << s.error_message();
    EXPECT_TRUE(within(begin)) << "GetRigStatus took too long";

    begin = std::chrono::steady_clock::now();
    grpc::ClientContext health_context;
    health_context.set_deadline(std::chrono::system_clock::now() + 10s);
    grpc::health::v1::HealthCheckResponse healthy;
    s = health->Check(&health_context, {}, &healthy);
    EXPECT_TRUE(s.ok()) << s.error_code() << " " << s.error_message();
    EXPECT_TRUE(within(begin)) << "health Check took too long";

    begin = std::chrono::steady_clock::now();
    v1::PauseSessionRequest pause;
    pause.set_session_id(id);
    pause.set_mode(v1::PAUSE_MODE_IMMEDIATE);
    v1::PauseSessionResponse paused;
    s = rig.control().PauseSession(DaemonRig::Context(kOperatorToken, 10s).get(), pause, &paused);
    ASSERT_TRUE(s.ok()) << s.error_code() << " " << s.error_message() << "\n" << rig.log();
    EXPECT_EQ(paused.session().state(), v1::SESSION_STATE_PAUSED);
    EXPECT_TRUE(within(begin)) << "PauseSession took too long";

    begin = std::chrono::steady_clock::now();
    v1::ResumeSessionRequest resume;
    resume.set_session_id(id);
    v1::ResumeSessionResponse resumed;
    s = rig.control().ResumeSession(DaemonRig::Context(kOperatorToken, 10s).get(), resume,
                                    &resumed);
    ASSERT_TRUE(s.ok()) << s.error_code() << " " << s.error_message();
    EXPECT_TRUE(within(begin)) << "ResumeSession took too long";
  }
  // Control before analysis (issue 40): under the load the control plane's threads run ahead of
  // Interpolate's loop, and those ahead of the streams' threads (nice values from /proc); and
  // GetRigStatus' median stays within a generous bound of the idle one (the bench's goal is 3×).
  const double loaded_ms = MedianRigStatusMs(rig, 40);
  int control = 0, interpolate = 0, pump = 0, threads = 0;
  for (const ThreadNice& t : Threads(rig.daemon()->pid())) {
    ++threads;
    if (t.name == "ctl-plane") {
      ++control;
      EXPECT_LE(t.nice, 0) << "a control plane thread";
      // Its short slice lets it preempt an analyst's thread when it wakes (thread_priority.h).
      if (KernelTakesSlices() && t.slice_ns >= 0) {
        EXPECT_EQ(t.slice_ns, 100'000) << "a control plane thread's slice";
      }
    } else if (t.name == "interp-loop" || t.name == "interp-slow") {
      ++interpolate;
      EXPECT_EQ(t.nice, 5) << t.name;
    } else if (t.name == "stream-pump") {
      ++pump;
      EXPECT_EQ(t.nice, 10) << "a stream pump thread";
    }
  }
  EXPECT_EQ(control, 2) << "the control plane's threads, named ctl-plane";
  EXPECT_GE(interpolate, 2) << "Interpolate's loop and slow lane";
  // The watches and followers (280 of the 400) run on the stream pump's threads, at nice 10, and
  // hold none while they wait (issue 40: before, each held a thread of gRPC's pool at nice 10).
  EXPECT_GE(pump, 1) << "the stream pump's threads, named stream-pump";
  EXPECT_LT(threads, kStreams * 7 / 10) << "the waiting watches and followers hold no thread";
  EXPECT_LT(loaded_ms, 10 * idle_ms + 10)
      << "GetRigStatus median " << loaded_ms << " ms under load, " << idle_ms << " ms idle";
  std::printf(
      "GetRigStatus median: idle %.3f ms, with %d streams and 2 Interpolate clients %.3f ms\n",
      idle_ms, kStreams, loaded_ms);

  stop = true;
  for (std::thread& t : clients) t.join();
  EXPECT_GT(interpolated.load(), 0);
  for (Held& h : held) h.context->TryCancel();
  op.Stop();
  v1::AbortSessionRequest abort;
  abort.set_session_id(id);
  abort.set_reason("test done");
  v1::AbortSessionResponse aborted;
  (void)rig.control().AbortSession(DaemonRig::Context().get(), abort, &aborted);

  // The session ended: the followers' streams end, each with every reading the store holds.
  for (std::thread& t : followers) t.join();
  std::vector<std::int64_t> stored;
  {
    v1::StreamReadingsRequest r;
    r.set_session_id(id);
    auto context = DaemonRig::Context(kAnalystToken, 30s);
    auto stream = rig.data().StreamReadings(context.get(), r);
    v1::Reading reading;
    while (stream->Read(&reading)) stored.push_back(reading.id());
    ASSERT_TRUE(stream->Finish().ok());
  }
  EXPECT_GT(stored.size(), 2u);
  for (const std::vector<std::int64_t>& ids : followed) EXPECT_EQ(ids, stored);
}

}  // namespace
}  // namespace brdf::testing
