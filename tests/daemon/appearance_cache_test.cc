// RenderAppearance's cache of answers, in process over gRPC on loopback: a real SQLite store
// filled through storage's API, the real IndexCache and InterpolationService behind a
// grpc::Server, and the generated client stub. The service's counters (appearance_renders,
// appearance_reuses) tell a render from an answer served again:
//   - the same request again is answered with the same bytes, without rendering, and those bytes
//     are a render's (an equivalent request that misses the cache renders the same bytes);
//   - another sphere size, other illuminants, another light render again, and the least recently
//     used answer goes once more than kAppearanceCacheEntries are kept;
//   - a reading that lands (handed over as the rig does, IndexCache::OnReading) makes the same
//     request render again, over the grown snapshot;
//   - identical requests at the same time render once, all answered with the same bytes;
//   - a call whose render is cancelled before it starts (every work permit taken) leaves it to
//     an identical call, which renders it.
#include <google/protobuf/io/coded_stream.h>
#include <google/protobuf/io/zero_copy_stream_impl_lite.h>
#include <grpcpp/grpcpp.h>
#include <gtest/gtest.h>

#include <chrono>
#include <functional>
#include <map>
#include <memory>
#include <random>
#include <string>
#include <thread>
#include <vector>

#include "brdf/v1/brdf.grpc.pb.h"
#include "daemon/auth.h"
#include "daemon/index_cache.h"
#include "daemon/interpolate_loop.h"
#include "daemon/service_common.h"
#include "daemon/service_interpolation.h"
#include "storage/session_store.h"
#include "tests/support/test_env.h"

namespace brdf::daemon {
namespace {

using namespace std::chrono_literals;

class AppearanceCacheTest : public ::testing::Test {
 protected:
  void SetUp() override {
    auto store = storage::SessionStore::Open(dir_.file("appearance.db").string());
    ASSERT_TRUE(store.ok()) << store.status().ToString();
    store_ = std::move(*store);
    cache_ = std::make_unique<IndexCache>(store_);
    service_ = std::make_unique<InterpolationService>(*cache_, auth_, stopping_, streams_);

    grpc::ServerBuilder builder;
    int port = 0;
    builder.AddListeningPort("127.0.0.1:0", grpc::InsecureServerCredentials(), &port);
    builder.SetMaxReceiveMessageSize(kMaxReceiveMessageBytes);
    builder.RegisterService(service_.get());
    loop_ = std::make_unique<InterpolateLoop>(*service_, 1);
    loop_->AddQueues(builder);
    server_ = builder.BuildAndStart();
    ASSERT_TRUE(server_ != nullptr && port > 0);
    loop_->Start();
    grpc::ChannelArguments args;
    args.SetMaxReceiveMessageSize(-1);
    stub_ = v1::Interpolation::NewStub(grpc::CreateCustomChannel(
        "127.0.0.1:" + std::to_string(port), grpc::InsecureChannelCredentials(), args));
  }

  void TearDown() override {
    stopping_.Stop();
    loop_->BeginShutdown();
    if (server_) server_->Shutdown(std::chrono::system_clock::now() + 2s);
    loop_->Stop();
  }

  // A session: a white reference, a dark, then `samples` sample readings at random directions
  // (θi, θo in [0, 80], φ in [0, 180]), room for `extra` more. Returns its id.
  std::int64_t MakeSession(int samples, int extra) {
    storage::NewSession s;
    s.name = "appearance cache test";
    s.plan_kind = "pose_list";
    s.plan_json = R"({"poseList": {"poses": [{"alpha": 0, "beta": 0, "delta": 0}]}})";
    s.created_by_role = "operator";
    s.white_reflectance = 0.99;
    std::vector<storage::StepRecord> steps;
    for (int i = 0; i < samples + 2 + extra; ++i) {
      storage::StepRecord r;
      r.step_index = i;
      r.kind = i == 0   ? storage::StepKind::kReference
               : i == 1 ? storage::StepKind::kDark
                        : storage::StepKind::kSample;
      steps.push_back(r);
    }
    Result<std::int64_t> id = store_->CreateSession(s, steps);
    EXPECT_TRUE(id.ok()) << id.status().ToString();
    EXPECT_TRUE(store_->SetSessionState(*id, SessionState::kRunning, "test").ok());
    reference_ = AddReading(*id, storage::ReadingKind::kReference, {10, 0, 10, 180}, 1.0).id;
    dark_ = AddReading(*id, storage::ReadingKind::kDark, {}, 0.001).id;
    for (int i = 0; i < samples; ++i) AddSample(*id);
    return *id;
  }

  // Stores a reading at the session's next step; returns it with its id.
  storage::ReadingRecord AddReading(std::int64_t session, storage::ReadingKind kind,
                                    const Directions& d, double level) {
    storage::ReadingRecord r;
    r.kind = kind;
    r.directions = d;
    r.grid = WavelengthGrid::Pr650();
    r.spectrum.assign(static_cast<std::size_t>(r.grid.count), level);
    if (kind == storage::ReadingKind::kSample) {
      r.reference_reading_id = reference_;
      r.dark_reading_id = dark_;
    }
    Result<std::int64_t> id = store_->CompleteStepWithReading(session, next_step_[session]++, r);
    EXPECT_TRUE(id.ok()) << id.status().ToString();
    r.id = id.ok() ? *id : 0;
    r.session_id = session;
    return r;
  }
  storage::ReadingRecord AddSample(std::int64_t session) {
    std::uniform_real_distribution<double> theta(0, 80);
    std::uniform_real_distribution<double> phi(0, 180);
    const double ti = theta(rng_), to = theta(rng_), p = phi(rng_);
    return AddReading(session, storage::ReadingKind::kSample, {ti, 0, to, p}, 0.05 + 0.1 * ti / 80);
  }

  grpc::Status Render(const v1::AppearanceRequest& request, v1::AppearanceResponse* response) {
    grpc::ClientContext context;
    context.set_deadline(std::chrono::system_clock::now() + 60s);
    return stub_->RenderAppearance(&context, request, response);
  }

  // The answer's bytes (deterministic), or a failure naming the call's error.
  std::string RenderBytes(const v1::AppearanceRequest& request) {
    v1::AppearanceResponse response;
    const grpc::Status st = Render(request, &response);
    EXPECT_TRUE(st.ok()) << st.error_message();
    EXPECT_GT(response.images_size(), 0);
    return Bytes(response);
  }

  static std::string Bytes(const v1::AppearanceResponse& response) {
    std::string bytes;
    {
      google::protobuf::io::StringOutputStream stream(&bytes);
      google::protobuf::io::CodedOutputStream coded(&stream);
      coded.SetSerializationDeterministic(true);
      response.SerializeToCodedStream(&coded);
    }
    return bytes;
  }

  static v1::AppearanceRequest Request(std::int64_t session, std::uint32_t sphere_size) {
    v1::AppearanceRequest r;
    r.set_session_id(std::to_string(session));
    r.set_sphere_size(sphere_size);
    r.mutable_options()->set_mirror_phi(true);
    return r;
  }

  std::uint64_t renders() const { return service_->appearance_renders(); }
  std::uint64_t reuses() const { return service_->appearance_reuses(); }

  testing::TempDir dir_{"appearance-cache-test"};
  std::shared_ptr<storage::SessionStore> store_;
  std::unique_ptr<IndexCache> cache_;
  Authenticator auth_{{}};
  StopSignal stopping_;
  StreamRegistry streams_{daemon::ServerConfig{}, false};
  std::unique_ptr<InterpolationService> service_;
  std::unique_ptr<InterpolateLoop> loop_;
  std::unique_ptr<grpc::Server> server_;
  std::unique_ptr<v1::Interpolation::Stub> stub_;
  std::mt19937_64 rng_{7};
  std::map<std::int64_t, int> next_step_;
  std::int64_t reference_ = 0;
  std::int64_t dark_ = 0;
};

TEST_F(AppearanceCacheTest, TheSameRequestAgainIsServedFromTheCacheWithTheSameBytes) {
  const std::int64_t session = MakeSession(200, 0);
  const v1::AppearanceRequest request = Request(session, 0);

  const std::string first = RenderBytes(request);
  EXPECT_EQ(renders(), 1u);
  EXPECT_EQ(reuses(), 0u);
  const std::string again = RenderBytes(request);
  EXPECT_EQ(renders(), 1u) << "the same request on the same snapshot rendered again";
  EXPECT_EQ(reuses(), 1u);
  EXPECT_TRUE(again == first) << "the cached answer differs from the render";

  // sphere_size 128 is the default's (0) answer but other request bytes: it misses the cache and
  // renders, to the same bytes.
  const std::string rendered = RenderBytes(Request(session, kDefaultAppearanceSphere));
  EXPECT_EQ(renders(), 2u);
  EXPECT_TRUE(rendered == first) << "a render of the same answer differs from the cached one";
}

TEST_F(AppearanceCacheTest, OtherOptionsRenderAgainAndTheLeastRecentlyUsedGoes) {
  const std::int64_t session = MakeSession(120, 0);
  v1::AppearanceRequest request = Request(session, 16);
  const std::string base = RenderBytes(request);
  ASSERT_EQ(renders(), 1u);

  v1::AppearanceRequest other_size = Request(session, 24);
  EXPECT_TRUE(RenderBytes(other_size) != base);
  EXPECT_EQ(renders(), 2u);

  v1::AppearanceRequest only_a = request;
  only_a.add_illuminants(v1::ILLUMINANT_A);
  EXPECT_TRUE(RenderBytes(only_a) != base);
  EXPECT_EQ(renders(), 3u);

  v1::AppearanceRequest head_on = request;
  for (double v : {0.0, 0.0, 1.0}) head_on.add_light(v);
  EXPECT_TRUE(RenderBytes(head_on) != base);
  EXPECT_EQ(renders(), 4u);

  v1::AppearanceRequest other_options = request;
  other_options.mutable_options()->set_reciprocity(true);
  RenderBytes(other_options);
  EXPECT_EQ(renders(), 5u);

  // Each of them again: served.
  for (const v1::AppearanceRequest* r : {&request, &other_size, &only_a, &head_on}) {
    RenderBytes(*r);
  }
  EXPECT_EQ(renders(), 5u);
  EXPECT_EQ(reuses(), 4u);

  // kAppearanceCacheEntries − 4 more answers fill the cache past its size: the least recently
  // used (`other_options`) goes, the most recently used (`head_on`) stays.
  const std::uint64_t before = renders();
  for (std::uint32_t size = 1; size <= kAppearanceCacheEntries - 4; ++size) {
    RenderBytes(Request(session, 30 + size));
  }
  EXPECT_EQ(renders(), before + kAppearanceCacheEntries - 4);
  RenderBytes(head_on);
  EXPECT_EQ(renders(), before + kAppearanceCacheEntries - 4) << "head_on was pushed out";
  RenderBytes(other_options);
  EXPECT_EQ(renders(), before + kAppearanceCacheEntries - 3) << "other_options was kept";
}

TEST_F(AppearanceCacheTest, AReadingThatLandsMakesTheSameRequestRenderAgain) {
  const std::int64_t session = MakeSession(150, 1);
  const v1::AppearanceRequest request = Request(session, 32);
  const std::string before = RenderBytes(request);
  RenderBytes(request);
  ASSERT_EQ(renders(), 1u);

  // A reading lands and is handed over, as the session manager does after each commit.
  const storage::ReadingRecord landed = AddSample(session);
  cache_->OnReading(session, landed);
  const std::string after = RenderBytes(request);
  EXPECT_EQ(renders(), 2u) << "the grown session's answer came from the cache";
  EXPECT_TRUE(after != before) << "the new reading changed nothing: the test shows nothing";
  // …and that answer is kept in turn.
  EXPECT_TRUE(RenderBytes(request) == after);
  EXPECT_EQ(renders(), 2u);
}

TEST_F(AppearanceCacheTest, IdenticalRequestsAtTheSameTimeRenderOnce) {
  const std::int64_t session = MakeSession(300, 0);
  const v1::AppearanceRequest request = Request(session, 96);
  constexpr int kCalls = 4;
  std::vector<std::string> answers(kCalls);
  std::vector<std::thread> calls;
  for (int i = 0; i < kCalls; ++i) {
    calls.emplace_back([&, i] { answers[static_cast<std::size_t>(i)] = RenderBytes(request); });
  }
  for (std::thread& t : calls) t.join();
  EXPECT_EQ(renders(), 1u);
  EXPECT_EQ(reuses(), static_cast<std::uint64_t>(kCalls - 1));
  for (int i = 1; i < kCalls; ++i) {
    EXPECT_TRUE(answers[static_cast<std::size_t>(i)] == answers[0]) << "answer " << i;
  }
}

TEST_F(AppearanceCacheTest, ARenderCancelledBeforeItStartsIsLeftToTheIdenticalCall) {
  const std::int64_t session = MakeSession(150, 0);
  const v1::AppearanceRequest request = Request(session, 48);
  auto until = [](const std::function<bool()>& done) {
    for (int i = 0; i < 3000 && !done(); ++i) std::this_thread::sleep_for(10ms);
    return done();
  };

  // Every work permit taken: a render cannot start.
  grpc::ServerContext idle;
  std::vector<std::unique_ptr<StreamRegistry::Slot>> held;
  for (int i = 0; i < streams_.work_permits(); ++i) {
    std::unique_ptr<StreamRegistry::Slot> slot;
    ASSERT_TRUE(streams_.Open(idle, nullptr, "test", &slot, /*computes=*/true).ok());
    held.push_back(std::move(slot));
  }
  const int open = streams_.open();

  // The first call would render (its flight is up), waiting for a permit; an identical one comes.
  grpc::ClientContext first_context;
  first_context.set_deadline(std::chrono::system_clock::now() + 60s);
  v1::AppearanceResponse first_response;
  grpc::Status first_status;
  std::thread first(
      [&] { first_status = stub_->RenderAppearance(&first_context, request, &first_response); });
  ASSERT_TRUE(until([&] { return service_->appearance_flights() == 1; }));
  std::string second;
  std::thread second_call([&] { second = RenderBytes(request); });
  ASSERT_TRUE(until([&] { return streams_.open() == open + 2; }));

  // The first is cancelled before it could render: the second renders, once the permits are free.
  first_context.TryCancel();
  first.join();
  EXPECT_EQ(first_status.error_code(), grpc::StatusCode::CANCELLED) << first_status.error_message();
  ASSERT_TRUE(until([&] { return streams_.open() == open + 1; }))
      << "the cancelled call's handler did not return";
  // Its flight is gone with it; the one up now is the second call's.
  EXPECT_TRUE(until([&] { return service_->appearance_flights() == 1; }))
      << "the second call did not take the render over";
  EXPECT_EQ(renders(), 0u);
  held.clear();
  second_call.join();
  EXPECT_EQ(renders(), 1u);
  EXPECT_EQ(service_->appearance_flights(), 0u);
  ASSERT_FALSE(second.empty());
  EXPECT_TRUE(RenderBytes(request) == second);
  EXPECT_EQ(renders(), 1u);
}

}  // namespace
}  // namespace brdf::daemon
