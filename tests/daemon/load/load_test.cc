// Load (ctest label "load"): while a session records on the simulated rig, watchers keep opening
// WatchSession streams and analysts keep calling Interpolate, InterpolateBatch, ListSessions and
// GetSession, for a bounded time. Every call must succeed (or end the way the client ended it),
// and brdfd's resident memory (VmRSS of the child, from /proc) must stay flat: the largest RSS of
// the second half may exceed that of the first half by at most kMaxRssGrowthKb. A leak of a
// kilobyte per call, or a subscription never freed, shows up well above that over thousands of
// calls; the index growing with the readings taken meanwhile stays far below it.
#include <gtest/gtest.h>

#include <algorithm>
#include <atomic>
#include <chrono>
#include <fstream>
#include <mutex>
#include <thread>
#include <vector>

#include "tests/support/daemon/test_rig.h"
#include "tests/support/plan_fixtures.h"

namespace brdf::testing {
namespace {

using namespace std::chrono_literals;
using grpc::StatusCode;

constexpr int kWatchers = 8;
constexpr int kAnalysts = 4;
constexpr auto kLoadDuration = 20s;
constexpr auto kWarmUp = 2s;  // not measured: gRPC's pools and the index fill up at first
constexpr long kMaxRssGrowthKb = 16 * 1024;

// Long enough to keep recording for the whole test (468 sample readings); aborted at the end.
const std::string kLongPlan = PlanFixture("load test")
                                  .SampleRotation({30, 30, 10}, {0, 60, 5}, 10)
                                  .Measurement(100, 1)
                                  .Retry(3, 0);

// Counts calls and keeps the first unexpected failures.
class Tally {
 public:
  void Ok() { ++ok_; }
  void Fail(const std::string& what) {
    std::lock_guard lock(mu_);
    if (failures_.size() < 10) failures_.push_back(what);
    ++failed_;
  }
  int ok() const { return ok_; }
  int failed() const { return failed_; }
  std::string failures() const {
    std::lock_guard lock(mu_);
    std::string out;
    for (const std::string& f : failures_) out += "  " + f + "\n";
    return out;
  }

 private:
  std::atomic<int> ok_{0};
  std::atomic<int> failed_{0};
  mutable std::mutex mu_;
  std::vector<std::string> failures_;
};

std::string Describe(const std::string& call, const grpc::Status& st) {
  return call + ": " + std::to_string(st.error_code()) + " " + st.error_message();
}

TEST(LoadTest, WatchersAndAnalystsWhileASessionRecordsKeepMemoryFlatAndCallsSucceed) {
  DaemonRig rig;
  Status st = rig.StartSim();
  ASSERT_TRUE(st.ok()) << st.ToString();
  st = rig.StartDaemon();
  ASSERT_TRUE(st.ok()) << st.ToString();
  Result<v1::Session> submitted = rig.Submit(kLongPlan);
  ASSERT_TRUE(submitted.ok()) << submitted.status().ToString();
  const std::string id = submitted->session_id();
  GrpcOperator op(rig, id);
  // Interpolation needs sample readings.
  v1::Session session = rig.WaitFor(
      id, [](const v1::Session& s) { return s.progress().done_samples() >= 3; }, 45s);
  ASSERT_GE(session.progress().done_samples(), 3u) << "state " << session.state() << "\n"
                                                   << rig.log();
  Result<std::vector<v1::Reading>> readings = rig.Readings(id);
  ASSERT_TRUE(readings.ok()) << readings.status().ToString();
  std::vector<v1::IsoDirection> measured;
  for (const v1::Reading& r : *readings) {
    if (r.kind() == v1::READING_KIND_SAMPLE) measured.push_back(r.iso());
  }
  ASSERT_FALSE(measured.empty());

  const pid_t pid = rig.daemon()->pid();
  std::atomic<bool> stop{false};
  Tally watches, analyses;
  std::atomic<int> events{0};
  std::vector<std::thread> threads;

  for (int w = 0; w < kWatchers; ++w) {
    threads.emplace_back([&, w] {
      std::unique_ptr<v1::Control::Stub> stub = v1::Control::NewStub(rig.channel());
      while (!stop) {
        // A stream of 0.5–1.2 s, then the client's deadline ends it: subscriptions come and go.
        auto ctx = DaemonRig::Context(kAnalystToken, std::chrono::milliseconds(500 + 100 * w));
        v1::WatchSessionRequest request;
        request.set_session_id(id);
        auto reader = stub->WatchSession(ctx.get(), request);
        v1::SessionEvent event;
        int got = 0;
        while (reader->Read(&event)) ++got;
        events += got;
        const grpc::Status done = reader->Finish();
        if (got > 0 && (done.error_code() == StatusCode::DEADLINE_EXCEEDED || done.ok())) {
          watches.Ok();
        } else {
          watches.Fail(Describe("WatchSession (" + std::to_string(got) + " events)", done));
        }
      }
    });
  }
  for (int a = 0; a < kAnalysts; ++a) {
    threads.emplace_back([&, a] {
      std::unique_ptr<v1::Control::Stub> control = v1::Control::NewStub(rig.channel());
      std::unique_ptr<v1::Interpolation::Stub> interpolation =
          v1::Interpolation::NewStub(rig.channel());
      for (std::size_t n = static_cast<std::size_t>(a); !stop; ++n) {
        const v1::IsoDirection& at = measured[n % measured.size()];
        v1::InterpolateRequest one;
        one.set_session_id(id);
        *one.mutable_direction()->mutable_iso() = at;
        v1::InterpolateResponse answer;
        grpc::Status s =
            interpolation->Interpolate(DaemonRig::Context(kAnalystToken, 20s).get(), one, &answer);
        s.ok() ? analyses.Ok() : analyses.Fail(Describe("Interpolate", s));

        v1::InterpolateBatchRequest batch;
        batch.set_session_id(id);
        batch.set_method(v1::INTERPOLATION_METHOD_NEAREST);
        for (int i = 0; i < 64; ++i) {
          v1::IsoDirection* d = batch.add_directions()->mutable_iso();
          d->set_theta_i(at.theta_i());
          d->set_theta_o(std::min(90.0, at.theta_o() + 0.1 * i));
          d->set_phi(at.phi());
        }
        {
          auto ctx = DaemonRig::Context(kAnalystToken, 20s);
          auto reader = interpolation->InterpolateBatch(ctx.get(), batch);
          v1::InterpolateBatchChunk chunk;
          int results = 0;
          while (reader->Read(&chunk)) results += chunk.results_size();
          s = reader->Finish();
          (s.ok() && results == 64)
              ? analyses.Ok()
              : analyses.Fail(Describe("InterpolateBatch (" + std::to_string(results) + ")", s));
        }
        v1::ListSessionsResponse listed;
        s = control->ListSessions(DaemonRig::Context(kAnalystToken, 20s).get(), {}, &listed);
        s.ok() ? analyses.Ok() : analyses.Fail(Describe("ListSessions", s));
        v1::GetSessionRequest get;
        get.set_session_id(id);
        v1::Session got;
        s = control->GetSession(DaemonRig::Context(kAnalystToken, 20s).get(), get, &got);
        s.ok() ? analyses.Ok() : analyses.Fail(Describe("GetSession", s));
      }
    });
  }

  // Sample the daemon's memory while the load runs.
  std::vector<std::pair<std::chrono::steady_clock::duration, long>> samples;
  const auto begin = std::chrono::steady_clock::now();
  while (std::chrono::steady_clock::now() - begin < kLoadDuration) {
    const long rss = ResidentKb(pid);
    ASSERT_GT(rss, 0) << "brdfd is gone\n" << rig.log();
    samples.emplace_back(std::chrono::steady_clock::now() - begin, rss);
    std::this_thread::sleep_for(250ms);
  }
  stop = true;
  for (std::thread& t : threads) t.join();

  long first_half = 0, second_half = 0;
  const auto middle = kWarmUp + (kLoadDuration - kWarmUp) / 2;
  for (const auto& [at, rss] : samples) {
    if (at < kWarmUp) continue;
    (at < middle ? first_half : second_half) =
        std::max(at < middle ? first_half : second_half, rss);
  }
  const v1::Session after = *rig.Get(id);
  std::cout << "load: " << watches.ok() << " watch streams (" << events << " events), "
            << analyses.ok() << " analyst calls, "
            << after.progress().done_samples() - session.progress().done_samples()
            << " readings recorded meanwhile; VmRSS max " << first_half << " kB (first half), "
            << second_half << " kB (second half)\n";

  EXPECT_EQ(watches.failed(), 0) << watches.failures();
  EXPECT_EQ(analyses.failed(), 0) << analyses.failures();
  // The load really ran (generous floors for a loaded 2-core machine).
  EXPECT_GE(watches.ok(), kWatchers * 3);
  EXPECT_GE(analyses.ok(), kAnalysts * 8);
  // The session kept recording under load.
  EXPECT_GT(after.progress().done_samples(), session.progress().done_samples());
  EXPECT_FALSE(IsTerminal(after.state())) << "the plan ended early: make it longer";
  ASSERT_GT(first_half, 0);
  ASSERT_GT(second_half, 0);
  EXPECT_LT(second_half - first_half, kMaxRssGrowthKb)
      << "brdfd's memory grew from " << first_half << " kB to " << second_half << " kB";

  v1::AbortSessionRequest abort;
  abort.set_session_id(id);
  abort.set_reason("load test over");
  v1::AbortSessionResponse aborted;
  grpc::Status done = rig.control().AbortSession(DaemonRig::Context().get(), abort, &aborted);
  EXPECT_TRUE(done.ok()) << done.error_message();
  op.Stop();
  Result<int> code = rig.StopDaemon();
  ASSERT_TRUE(code.ok()) << code.status().ToString();
  EXPECT_EQ(*code, 0) << rig.log();
}

}  // namespace
}  // namespace brdf::testing
