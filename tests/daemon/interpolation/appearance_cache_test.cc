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
#include "daemon/api/common.h"
#include "daemon/api/interpolate_loop.h"
#include "daemon/api/interpolation.h"
#include "daemon/index/cache.h"
#include "daemon/rpc/auth.h"
#include "storage/session_store.h"
#include "tests/daemon/interpolation/service_test.h"

namespace brdf::daemon {
namespace {

using namespace std::chrono_literals;

class AppearanceCacheTest : public testing::InterpolationServiceTest {
 protected:
  AppearanceCacheTest() : InterpolationServiceTest("appearance-cache-test", 7) {}

  // Brighter towards grazing incidence: a session's renders differ with its readings.
  double SampleLevel(double theta_i) const override { return 0.05 + 0.1 * theta_i / 80; }

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
