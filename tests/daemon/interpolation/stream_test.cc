// The Interpolation service in process, over gRPC on loopback: a real SQLite store filled through
// storage's API, the real IndexCache and InterpolationService behind a grpc::Server with
// Interpolate served by an InterpolateLoop, and the generated client stub. Checks that
// InterpolateBatch streams its answer chunk by chunk under the client's flow control (a server
// interceptor counts the chunks the service has written), the precise errors of both RPCs, that
// the per-session index takes in new readings by appending them (the cache's counters) instead of
// reading the session again, and the loop: concurrent calls while readings land (answered on the
// loop or, after each new reading, in its slow lane), and a shutdown with calls in flight.
#include <grpcpp/grpcpp.h>
#include <grpcpp/support/server_interceptor.h>
#include <gtest/gtest.h>

#include <algorithm>
#include <atomic>
#include <chrono>
#include <cmath>
#include <limits>
#include <memory>
#include <random>
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
#include "tests/support/test_env.h"

namespace brdf::daemon {
namespace {

using namespace std::chrono_literals;

// Counts the messages the service handlers have started to write (PRE_SEND_MESSAGE), all RPCs.
class CountingInterceptor final : public grpc::experimental::Interceptor {
 public:
  explicit CountingInterceptor(std::atomic<int>& sent) : sent_(sent) {}
  void Intercept(grpc::experimental::InterceptorBatchMethods* methods) override {
    if (methods->QueryInterceptionHookPoint(
            grpc::experimental::InterceptionHookPoints::PRE_SEND_MESSAGE)) {
      ++sent_;
    }
    methods->Proceed();
  }

 private:
  std::atomic<int>& sent_;
};

class CountingFactory final : public grpc::experimental::ServerInterceptorFactoryInterface {
 public:
  explicit CountingFactory(std::atomic<int>& sent) : sent_(sent) {}
  grpc::experimental::Interceptor* CreateServerInterceptor(
      grpc::experimental::ServerRpcInfo*) override {
    return new CountingInterceptor(sent_);
  }

 private:
  std::atomic<int>& sent_;
};

class InterpStreamTest : public testing::InterpolationServiceTest {
 protected:
  InterpStreamTest() : InterpolationServiceTest("interp-stream-test", 5) {}

  InterceptorFactories ServerInterceptors() override {
    InterceptorFactories creators;
    creators.push_back(std::make_unique<CountingFactory>(sent_));
    return creators;
  }
  // No BDP probing: the stream's flow-control window stays at its initial 64 KiB, so a client
  // that stops reading holds the server back after a few chunks.
  void ChannelArgumentsFor(grpc::ChannelArguments& args) override {
    args.SetInt(GRPC_ARG_HTTP2_BDP_PROBE, 0);
  }

  static std::unique_ptr<grpc::ClientContext> Context(std::chrono::milliseconds deadline = 20s) {
    auto c = std::make_unique<grpc::ClientContext>();
    c->set_deadline(std::chrono::system_clock::now() + deadline);
    return c;
  }

  static v1::DirectionQuery Iso(double theta_i, double theta_o, double phi) {
    v1::DirectionQuery q;
    q.mutable_iso()->set_theta_i(theta_i);
    q.mutable_iso()->set_theta_o(theta_o);
    q.mutable_iso()->set_phi(phi);
    return q;
  }

  grpc::Status Single(const std::string& session, const v1::DirectionQuery& direction,
                      v1::InterpolateResponse* response = nullptr) {
    v1::InterpolateRequest request;
    request.set_session_id(session);
    *request.mutable_direction() = direction;
    v1::InterpolateResponse ignored;
    auto context = Context();
    return stub_->Interpolate(context.get(), request, response ? response : &ignored);
  }

  // The reading the nearest-neighbour method answers with at `direction`; −1 when the call fails
  // or does not answer with exactly one vertex.
  std::int64_t NearestReadingAt(const std::string& session, const v1::DirectionQuery& direction) {
    v1::InterpolateRequest request;
    request.set_session_id(session);
    *request.mutable_direction() = direction;
    request.set_method(v1::INTERPOLATION_METHOD_NEAREST);
    v1::InterpolateResponse response;
    auto context = Context();
    if (!stub_->Interpolate(context.get(), request, &response).ok()) return -1;
    if (response.result().vertices_size() != 1) return -1;
    return response.result().vertices(0).reading_id();
  }

  // Runs a whole batch; the chunks through `chunks`.
  grpc::Status Batch(const v1::InterpolateBatchRequest& request,
                     std::vector<v1::InterpolateBatchChunk>* chunks = nullptr) {
    auto context = Context();
    auto reader = stub_->InterpolateBatch(context.get(), request);
    v1::InterpolateBatchChunk chunk;
    while (reader->Read(&chunk)) {
      if (chunks != nullptr) chunks->push_back(chunk);
    }
    return reader->Finish();
  }

  std::atomic<int> sent_{0};  // messages the service handlers started to write
};

TEST_F(InterpStreamTest, BatchStreamsChunkByChunkUnderTheClientsFlowControl) {
  const std::string session = std::to_string(MakeSession(300));
  constexpr int kChunk = 64;
  constexpr int kDirections = 200 * kChunk;  // 200 chunks of ~80 KB (101 bands + provenance)
  v1::InterpolateBatchRequest request;
  request.set_session_id(session);
  request.set_chunk_size(kChunk);
  std::uniform_real_distribution<double> theta(0, 80);
  std::uniform_real_distribution<double> phi(0, 180);
  std::vector<v1::DirectionQuery> asked;
  for (int i = 0; i < kDirections; ++i) {
    asked.push_back(Iso(theta(rng_), theta(rng_), phi(rng_)));
    *request.add_directions() = asked.back();
  }

  // The chunks' sizes: 8 results, then each twice the last up to chunk_size (brdf.proto), and a
  // last one with what is left.
  std::vector<int> sizes;
  for (int left = kDirections, size = 8; left > 0; size = std::min(kChunk, 2 * size)) {
    sizes.push_back(std::min(size, left));
    left -= sizes.back();
  }

  auto context = Context(60s);
  auto reader = stub_->InterpolateBatch(context.get(), request);
  v1::InterpolateBatchChunk chunk;
  ASSERT_TRUE(reader->Read(&chunk));
  EXPECT_EQ(chunk.first_index(), 0u);
  EXPECT_EQ(chunk.results_size(), sizes[0]);
  // The client stops reading. The server must stop writing once the stream's window is full:
  // its count of written chunks levels off far below the 200 of the answer (were the answer
  // queued whole, it would reach 200 within milliseconds).
  int seen = sent_.load();
  for (int i = 0; i < 40; ++i) {  // ~2 s for a runaway server to show itself
    std::this_thread::sleep_for(50ms);
    seen = sent_.load();
    if (seen >= kDirections / kChunk) break;
  }
  EXPECT_LT(seen, 40) << "the server wrote " << seen
                      << " chunks while the client read one: it does not wait for flow control";

  // Reading on: every result, in order, each chunk starting where the previous one ended.
  int next = sizes[0];
  int chunks = 1;
  while (reader->Read(&chunk)) {
    ASSERT_LT(static_cast<std::size_t>(chunks), sizes.size());
    EXPECT_EQ(chunk.results_size(), sizes[static_cast<std::size_t>(chunks)]);
    ++chunks;
    ASSERT_EQ(static_cast<int>(chunk.first_index()), next);
    for (int i = 0; i < chunk.results_size(); ++i) {
      const v1::InterpolationResult& r = chunk.results(i);
      EXPECT_EQ(r.query().iso().theta_i(),
                asked[static_cast<std::size_t>(next + i)].iso().theta_i());
    }
    next += chunk.results_size();
  }
  const grpc::Status finished = reader->Finish();
  ASSERT_TRUE(finished.ok()) << finished.error_message();
  EXPECT_EQ(next, kDirections);
  EXPECT_EQ(static_cast<std::size_t>(chunks), sizes.size());
  EXPECT_EQ(static_cast<std::size_t>(sent_.load()), sizes.size());

  // The default chunk size (8, 16, …, 256, 256), and a last chunk that is short.
  v1::InterpolateBatchRequest small;
  small.set_session_id(session);
  const int grown = 8 + 16 + 32 + 64 + 128;
  const int n = grown + 2 * static_cast<int>(kDefaultChunkSize) + 3;
  for (int i = 0; i < n; ++i) *small.add_directions() = asked[static_cast<std::size_t>(i)];
  std::vector<v1::InterpolateBatchChunk> got;
  ASSERT_TRUE(Batch(small, &got).ok());
  ASSERT_EQ(got.size(), 8u);
  EXPECT_EQ(got[0].results_size(), 8);
  EXPECT_EQ(got[4].results_size(), 128);
  EXPECT_EQ(got[5].first_index(), static_cast<std::uint32_t>(grown));
  EXPECT_EQ(got[5].results_size(), static_cast<int>(kDefaultChunkSize));
  EXPECT_EQ(got[6].results_size(), static_cast<int>(kDefaultChunkSize));
  EXPECT_EQ(got[7].first_index(), grown + 2 * kDefaultChunkSize);
  EXPECT_EQ(got[7].results_size(), 3);
}

TEST_F(InterpStreamTest, ErrorsNameTheFieldAndTheIndex) {
  const std::string session = std::to_string(MakeSession(40));
  const double nan = std::numeric_limits<double>::quiet_NaN();
  const double inf = std::numeric_limits<double>::infinity();
  auto expect = [](const grpc::Status& st, grpc::StatusCode code, const std::string& field) {
    EXPECT_EQ(st.error_code(), code) << st.error_message();
    EXPECT_EQ(st.error_message().rfind(field, 0), 0u)
        << "'" << st.error_message() << "' does not start with " << field;
  };

  // Interpolate.
  ASSERT_TRUE(Single(session, Iso(30, 30, 90)).ok());
  expect(Single(session, Iso(nan, 30, 90)), grpc::StatusCode::INVALID_ARGUMENT,
         "direction.iso.theta_i: must be a finite angle");
  expect(Single(session, Iso(30, -inf, 90)), grpc::StatusCode::INVALID_ARGUMENT,
         "direction.iso.theta_o: must be a finite angle");
  expect(Single(session, Iso(30, 91, 90)), grpc::StatusCode::INVALID_ARGUMENT,
         "direction.iso.theta_o: 91° is outside [0, 90]");
  expect(Single(session, Iso(30, 30, 400)), grpc::StatusCode::INVALID_ARGUMENT,
         "direction.iso.phi: 400° is outside");
  expect(Single(session, v1::DirectionQuery()), grpc::StatusCode::INVALID_ARGUMENT,
         "direction: no direction");
  v1::DirectionQuery four;
  four.mutable_four()->set_theta_i(20);
  four.mutable_four()->set_phi_i(nan);
  expect(Single(session, four), grpc::StatusCode::INVALID_ARGUMENT,
         "direction.four.phi_i: must be a finite angle");
  expect(Single("987654", Iso(30, 30, 90)), grpc::StatusCode::NOT_FOUND, "");
  expect(Single("abc", Iso(30, 30, 90)), grpc::StatusCode::INVALID_ARGUMENT, "session_id");
  EXPECT_NE(Single("987654", Iso(30, 30, 90)).error_message().find("987654"), std::string::npos);

  // InterpolateBatch: the index of the offending direction, the first one wins.
  const int sent_before = sent_.load();  // (the good Interpolate above sent its answer)
  v1::InterpolateBatchRequest batch;
  batch.set_session_id(session);
  for (int i = 0; i < 10; ++i) *batch.add_directions() = Iso(10 + i, 20, 30);
  std::vector<v1::InterpolateBatchChunk> good;
  ASSERT_TRUE(Batch(batch, &good).ok());
  ASSERT_EQ(good.size(), 2u);  // 8 results, then 2 (the first chunk holds 8)
  v1::InterpolateBatchRequest bad = batch;
  bad.mutable_directions(7)->mutable_iso()->set_phi(inf);
  bad.mutable_directions(8)->mutable_iso()->set_theta_i(nan);
  expect(Batch(bad), grpc::StatusCode::INVALID_ARGUMENT,
         "directions[7].iso.phi: must be a finite angle");
  bad = batch;
  bad.mutable_directions(3)->mutable_iso()->set_theta_o(90.5);
  expect(Batch(bad), grpc::StatusCode::INVALID_ARGUMENT, "directions[3].iso.theta_o: 90.5°");
  bad = batch;
  bad.mutable_directions(9)->clear_iso();
  expect(Batch(bad), grpc::StatusCode::INVALID_ARGUMENT, "directions[9]: no direction");

  v1::InterpolateBatchRequest empty;
  empty.set_session_id(session);
  expect(Batch(empty), grpc::StatusCode::INVALID_ARGUMENT, "directions: empty");

  v1::InterpolateBatchRequest huge;
  huge.set_session_id(session);
  for (int i = 0; i < kMaxBatchDirections + 1; ++i) *huge.add_directions() = Iso(10, 20, 30);
  expect(Batch(huge), grpc::StatusCode::RESOURCE_EXHAUSTED, "directions: 100001 directions");

  v1::InterpolateBatchRequest chunky = batch;
  chunky.set_chunk_size(kMaxChunkSize + 1);
  expect(Batch(chunky), grpc::StatusCode::INVALID_ARGUMENT, "chunk_size");

  v1::InterpolateBatchRequest unknown = batch;
  unknown.set_session_id("987654");
  expect(Batch(unknown), grpc::StatusCode::NOT_FOUND, "");
  // Only the good batch wrote chunks: every error comes before any work.
  EXPECT_EQ(sent_.load(), sent_before + 2);
}

TEST_F(InterpStreamTest, NewReadingsAreAppendedToTheIndexNotReadAgain) {
  const std::int64_t id = MakeSession(50, /*extra_steps=*/5);
  const std::string session = std::to_string(id);
  ASSERT_TRUE(Single(session, Iso(30, 30, 90)).ok());
  const IndexCache::Stats first = cache_->stats();
  EXPECT_EQ(first.loads, 1u);
  EXPECT_EQ(first.appends, 0u);
  EXPECT_EQ(first.readings_read, 52u);  // the reference, the dark and 50 samples

  // Nothing new: answered from the same index, nothing read.
  ASSERT_TRUE(Single(session, Iso(40, 20, 120)).ok());
  EXPECT_EQ(cache_->stats().readings_read, first.readings_read);
  EXPECT_EQ(cache_->stats().builds, first.builds);

  // Two readings land, handed over as the daemon's reading listener does; the very next query
  // sees the new one at its direction, having folded just those two in, with no store read.
  const storage::ReadingRecord a =
      AddReading(id, storage::ReadingKind::kSample, {33, 0, 44, 55}, 0.7);
  cache_->OnReading(id, a);
  const storage::ReadingRecord b =
      AddReading(id, storage::ReadingKind::kSample, {63, 0, 14, 150}, 0.2);
  cache_->OnReading(id, b);
  EXPECT_EQ(NearestReadingAt(session, Iso(33, 44, 55)), a.id);
  const IndexCache::Stats after = cache_->stats();
  EXPECT_EQ(after.readings_read, first.readings_read);
  EXPECT_EQ(after.readings_folded, first.readings_folded + 2);
  EXPECT_EQ(after.loads, 2u);
  EXPECT_EQ(after.appends, 1u);

  // The octant index over the same readings: built once more, nothing read.
  ASSERT_TRUE(Single(session, Iso(63, 14, 150)).ok());
  EXPECT_EQ(cache_->stats().readings_read, after.readings_read);
}

TEST_F(InterpStreamTest, ConcurrentCallsWhileReadingsLandAllSeeTheReadingsBeforeThem) {
  const std::int64_t id = MakeSession(60, /*extra_steps=*/20);
  const std::string session = std::to_string(id);
  ASSERT_TRUE(Single(session, Iso(30, 30, 90)).ok());
  std::atomic<bool> done{false};
  std::atomic<int> answered{0};
  std::vector<std::string> failures(4);
  std::vector<std::thread> clients;
  for (int c = 0; c < 4; ++c) {
    clients.emplace_back([&, c] {
      while (!done.load()) {
        grpc::Status st = Single(session, Iso(10 + c * 10, 40, 20 * c));
        if (!st.ok()) {
          failures[c] = st.error_message();
          return;
        }
        ++answered;
      }
    });
  }
  // Twenty readings land while the clients query: after each, the next query of the session
  // goes to the slow lane (the index is extended), the ones after it are answered on the loop.
  std::int64_t last_id = 0;
  for (int i = 0; i < 20; ++i) {
    const storage::ReadingRecord r =
        AddReading(id, storage::ReadingKind::kSample, {5.0 + 3 * i, 0, 70.0 - 2 * i, 7.0 * i}, 0.5);
    cache_->OnReading(id, r);
    last_id = r.id;
    std::this_thread::sleep_for(5ms);
  }
  done = true;
  for (std::thread& t : clients) t.join();
  for (const std::string& f : failures) EXPECT_EQ(f, "");
  EXPECT_GT(answered.load(), 20);
  // The next query sees the last reading: it is the nearest neighbour at its own direction.
  EXPECT_EQ(NearestReadingAt(session, Iso(5 + 3 * 19, 70 - 2 * 19, 7 * 19)), last_id);
  EXPECT_GE(cache_->stats().appends, 1u);
}

TEST_F(InterpStreamTest, ShutdownWithCallsInFlightEndsEveryCall) {
  const std::string hot = std::to_string(MakeSession(40));
  const std::string cold = std::to_string(MakeSession(2000));
  ASSERT_TRUE(Single(hot, Iso(30, 30, 90)).ok());
  // 64 calls at once: half on the session with an index (the loop), half on one whose index
  // is not loaded yet (the slow lane, one after another behind the first load).
  grpc::CompletionQueue queue;
  struct Call {
    grpc::ClientContext context;
    v1::InterpolateResponse response;
    grpc::Status status;
    std::unique_ptr<grpc::ClientAsyncResponseReader<v1::InterpolateResponse>> reader;
  };
  std::vector<std::unique_ptr<Call>> calls;
  for (int i = 0; i < 64; ++i) {
    auto call = std::make_unique<Call>();
    call->context.set_deadline(std::chrono::system_clock::now() + 20s);
    v1::InterpolateRequest request;
    request.set_session_id(i % 2 == 0 ? hot : cold);
    *request.mutable_direction() = Iso(20 + i % 40, 30, (3 * i) % 180);  // φ within [0, 180]
    call->reader = stub_->AsyncInterpolate(&call->context, request, &queue);
    call->reader->Finish(&call->response, &call->status, call.get());
    calls.push_back(std::move(call));
  }
  TearDown();  // the daemon's shutdown order: no new calls, the server, then the loop
  int ended = 0;
  void* tag = nullptr;
  bool ok = false;
  while (ended < 64 && queue.Next(&tag, &ok)) {
    ++ended;
    const grpc::Status& st = static_cast<Call*>(tag)->status;
    // Answered before the end, or ended by it; never left to run into its deadline.
    EXPECT_TRUE(st.ok() || st.error_code() == grpc::StatusCode::CANCELLED ||
                st.error_code() == grpc::StatusCode::UNAVAILABLE)
        << st.error_code() << " " << st.error_message();
  }
  EXPECT_EQ(ended, 64);
  queue.Shutdown();
  while (queue.Next(&tag, &ok)) {
  }
}

}  // namespace
}  // namespace brdf::daemon
