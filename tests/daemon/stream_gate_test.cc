// The gate in front of the services (issue 20): tokens are checked before a request is read
// (unauthenticated 15 MiB calls do not grow the daemon), errors quote at most a short printable
// prefix of a client's string, open streams are capped per token and per role with
// RESOURCE_EXHAUSTED naming the key while the control plane still answers, a stream whose client
// stops reading is cancelled after [server] stream_stall_timeout_s, and the caps the proto
// documents (chunk_size 1,024, page_size 1,000, chunk_bytes 4 MiB − 1 KiB) are the server's.
#include <gtest/gtest.h>

#include <chrono>
#include <fstream>
#include <thread>
#include <vector>

#include "daemon/api/common.h"
#include "grpc/health/v1/health.grpc.pb.h"
#include "tests/support/daemon/test_rig.h"
#include "tests/support/plan_fixtures.h"

namespace brdf::testing {
namespace {

using namespace std::chrono_literals;
using grpc::StatusCode;

constexpr const char* kSecondAnalystToken = "an2-token-5d1e0f7a99c34b12";

// The rig's configuration with `server_keys` added to [server] and a second analyst token.
std::string ConfigWith(const DaemonRig& rig, const std::string& server_keys) {
  std::string toml = DaemonConfigToml(rig.sim(), rig.database());
  const std::string listen = "listen = \"127.0.0.1:0\"\n";
  toml.insert(toml.find(listen) + listen.size(), server_keys);
  toml += std::string("\n[[auth.tokens]]\nname = \"second-analyst\"\nrole = \"analyst\"\n") +
          "token = \"" + kSecondAnalystToken + "\"\n";
  return toml;
}

class StreamGateTest : public ::testing::Test {
 protected:
  void Start(const std::string& server_keys) {
    Status st = rig_.StartSim();
    ASSERT_TRUE(st.ok()) << st.ToString();
    st = rig_.StartDaemon(ConfigWith(rig_, server_keys));
    ASSERT_TRUE(st.ok()) << st.ToString();
  }
  // A session to watch (queued, not started: it stays put).
  std::string QueuedSession() {
    Result<v1::Session> s =
        rig_.Submit(PlanFixture("gate").SampleRotation({30, 30, 10}, {0, 60, 30}, 10),
                    /*start_now=*/false);
    EXPECT_TRUE(s.ok()) << s.status().ToString();
    return s.ok() ? s->session_id() : "";
  }

  DaemonRig rig_;
};

// An open WatchSession stream: its first message read (the snapshot), or the refusal.
struct OpenWatch {
  std::unique_ptr<grpc::ClientContext> context;
  std::unique_ptr<grpc::ClientReader<v1::SessionEvent>> reader;
  bool open = false;
  grpc::Status refusal;
};

OpenWatch Watch(DaemonRig& rig, const std::string& token, const std::string& id) {
  OpenWatch w;
  w.context = DaemonRig::Context(token, 60s);
  v1::WatchSessionRequest request;
  request.set_session_id(id);
  w.reader = rig.control().WatchSession(w.context.get(), request);
  v1::SessionEvent first;
  w.open = w.reader->Read(&first);
  if (!w.open) w.refusal = w.reader->Finish();
  return w;
}

TEST_F(StreamGateTest, UnauthenticatedLargeRequestsAreRefusedBeforeTheyAreRead) {
  Start("");
  const pid_t pid = rig_.daemon()->pid();
  v1::RigStatus status;
  ASSERT_TRUE(rig_.control().GetRigStatus(DaemonRig::Context().get(), {}, &status).ok());
  const long before = ResidentKb(pid);
  ASSERT_GT(before, 0);

  v1::SubmitPlanRequest big;
  big.mutable_plan()->set_name(std::string(15 * 1024 * 1024, 'x'));
  std::vector<std::thread> callers;
  std::vector<grpc::Status> results(8);
  for (int i = 0; i < 8; ++i) {
    callers.emplace_back([&, i] {
      // No token at all, and a wrong one: both refused from the metadata.
      auto context = DaemonRig::Context(i % 2 == 0 ? "" : "not-a-token", 30s);
      v1::SubmitPlanResponse response;
      results[static_cast<std::size_t>(i)] =
          rig_.control().SubmitPlan(context.get(), big, &response);
    });
  }
  for (std::thread& t : callers) t.join();
  for (const grpc::Status& r : results) {
    EXPECT_EQ(r.error_code(), StatusCode::UNAUTHENTICATED) << r.error_message();
  }
  const long after = ResidentKb(pid);
  // Reading them would cost 8 × 15 MiB (and their parsing as much again): 120 MB and more. The
  // transport still takes in part of each body before the refusal goes out (HTTP/2 flow-control
  // windows): 1.4 to 19 MB in six runs on a loaded machine (2026-12-05), so the bound is a quarter
  // of the bodies, well apart from both.
  EXPECT_LT(after - before, 30 * 1024) << "VmRSS " << before << " kB → " << after << " kB";
  std::cout << "8 unauthenticated 15 MiB calls: VmRSS " << before << " kB → " << after << " kB\n";
}

TEST(ErrorTextTest, ClientStringsAreQuotedShortAndPrintableAndMessagesBounded) {
  EXPECT_EQ(daemon::PrintablePrefix("brdf.v1.Control"), "brdf.v1.Control");
  EXPECT_EQ(daemon::PrintablePrefix(std::string("a\x01\nb", 4)), "a??b");
  EXPECT_EQ(daemon::PrintablePrefix(std::string(100, 'x'), 8), "xxxxxxxx... (100 bytes)");
  const std::string short_message = "θi: out of range";
  EXPECT_EQ(daemon::BoundedMessage(short_message), short_message);
  std::string long_message;
  while (long_message.size() < 5000) long_message += "θ";  // two bytes each
  const std::string bounded = daemon::BoundedMessage(long_message);
  EXPECT_LE(bounded.size(), daemon::kMaxErrorMessageBytes);
  EXPECT_NE(bounded.find("(5000 bytes)"), std::string::npos) << bounded;
  EXPECT_EQ(bounded.rfind("θ... (", std::string::npos) + std::string("θ... (").size() +
                std::string("5000 bytes)").size(),
            bounded.size())
      << "cut at a character boundary";
}

TEST_F(StreamGateTest, ErrorsQuoteAShortPrintablePrefixOfAClientsString) {
  Start("");
  auto health = grpc::health::v1::Health::NewStub(rig_.channel());
  grpc::health::v1::HealthCheckRequest request;
  request.set_service(std::string(100 * 1024, 'n') + "\x01\x02");
  grpc::health::v1::HealthCheckResponse response;
  grpc::ClientContext context;
  const grpc::Status st = health->Check(&context, request, &response);
  EXPECT_EQ(st.error_code(), StatusCode::NOT_FOUND);
  EXPECT_LT(st.error_message().size(), 512u) << st.error_message().substr(0, 300);
  EXPECT_NE(st.error_message().find("(102402 bytes)"), std::string::npos) << st.error_message();
}

TEST_F(StreamGateTest, StreamCapsNameTheirKeysAndTheControlPlaneStillAnswers) {
  Start("max_streams_per_token = 3\nmax_streams_analyst = 5\n");
  const std::string id = QueuedSession();
  ASSERT_FALSE(id.empty());
  std::vector<OpenWatch> held;
  for (int i = 0; i < 3; ++i) {
    held.push_back(Watch(rig_, kAnalystToken, id));
    ASSERT_TRUE(held.back().open) << held.back().refusal.error_message();
  }
  OpenWatch fourth = Watch(rig_, kAnalystToken, id);
  ASSERT_FALSE(fourth.open);
  EXPECT_EQ(fourth.refusal.error_code(), StatusCode::RESOURCE_EXHAUSTED);
  EXPECT_NE(fourth.refusal.error_message().find("max_streams_per_token"), std::string::npos)
      << fourth.refusal.error_message();
  // The other analyst token: two more fit under the role's cap of five, the third does not.
  for (int i = 0; i < 2; ++i) {
    held.push_back(Watch(rig_, kSecondAnalystToken, id));
    ASSERT_TRUE(held.back().open) << held.back().refusal.error_message();
  }
  OpenWatch over = Watch(rig_, kSecondAnalystToken, id);
  ASSERT_FALSE(over.open);
  EXPECT_EQ(over.refusal.error_code(), StatusCode::RESOURCE_EXHAUSTED);
  EXPECT_NE(over.refusal.error_message().find("max_streams_analyst"), std::string::npos)
      << over.refusal.error_message();
  // The operator's streams have their own cap; its verbs and GetRigStatus answer.
  OpenWatch operator_watch = Watch(rig_, kOperatorToken, id);
  EXPECT_TRUE(operator_watch.open) << operator_watch.refusal.error_message();
  v1::RigStatus status;
  EXPECT_TRUE(rig_.control().GetRigStatus(DaemonRig::Context().get(), {}, &status).ok());
  v1::AbortSessionRequest abort;
  abort.set_session_id(id);
  abort.set_reason("gate test");
  v1::AbortSessionResponse aborted;
  const grpc::Status st = rig_.control().AbortSession(DaemonRig::Context().get(), abort, &aborted);
  ASSERT_TRUE(st.ok()) << st.error_message();
  // A closed stream frees its place.
  held.front().context->TryCancel();
  held.front().reader->Finish();
  bool reopened = false;
  for (int attempt = 0; attempt < 50 && !reopened; ++attempt) {
    OpenWatch again = Watch(rig_, kAnalystToken, id);
    reopened = again.open;
    if (!reopened) std::this_thread::sleep_for(100ms);
  }
  EXPECT_TRUE(reopened);
  for (OpenWatch& w : held) w.context->TryCancel();
}

TEST_F(StreamGateTest, PausingAPausedSessionSaysSo) {
  Start("");
  Result<v1::Session> s = rig_.Submit(
      PlanFixture("pause twice").SampleRotation({30, 30, 10}, {0, 60, 5}, 10).Measurement(100, 1));
  ASSERT_TRUE(s.ok()) << s.status().ToString();
  GrpcOperator op(rig_, s->session_id());
  rig_.WaitFor(s->session_id(), [](const v1::Session& x) {
    return x.state() == v1::SESSION_STATE_RUNNING || x.state() == v1::SESSION_STATE_PAUSED;
  });
  v1::PauseSessionRequest pause;
  pause.set_session_id(s->session_id());
  pause.set_mode(v1::PAUSE_MODE_IMMEDIATE);
  v1::PauseSessionResponse first;
  grpc::Status st = rig_.control().PauseSession(DaemonRig::Context().get(), pause, &first);
  ASSERT_TRUE(st.ok()) << st.error_message();
  EXPECT_EQ(first.session().state(), v1::SESSION_STATE_PAUSED);
  EXPECT_FALSE(first.already_paused());
  v1::PauseSessionResponse second;
  st = rig_.control().PauseSession(DaemonRig::Context().get(), pause, &second);
  ASSERT_TRUE(st.ok()) << st.error_message();
  EXPECT_TRUE(second.already_paused());
  op.Stop();
}

TEST_F(StreamGateTest, AStreamItsClientStopsReadingIsCancelledAfterTheStallTimeout) {
  Start("stream_stall_timeout_s = 1\n");
  Result<v1::Session> s = rig_.Submit(
      PlanFixture("stall").SampleRotation({30, 30, 10}, {0, 60, 5}, 10).Measurement(100, 1));
  ASSERT_TRUE(s.ok()) << s.status().ToString();
  GrpcOperator op(rig_, s->session_id());
  const v1::Session recorded = rig_.WaitFor(
      s->session_id(), [](const v1::Session& x) { return x.progress().done_samples() >= 2; }, 45s);
  ASSERT_GE(recorded.progress().done_samples(), 2u) << rig_.log();
  // ~24 MB of answers: far more than HTTP/2's windows hold while the client reads nothing.
  v1::InterpolateBatchRequest batch;
  batch.set_session_id(s->session_id());
  for (int d = 0; d < 20000; ++d) {
    v1::IsoDirection* at = batch.add_directions()->mutable_iso();
    at->set_theta_i(30);
    at->set_theta_o(10 + d % 60);
    at->set_phi(d % 180);
  }
  auto context = DaemonRig::Context(kAnalystToken, 60s);
  auto reader = rig_.interpolation().InterpolateBatch(context.get(), batch);
  std::this_thread::sleep_for(4s);  // the stall timeout (1 s) and the watchdog's round
  int results = 0;
  v1::InterpolateBatchChunk chunk;
  while (reader->Read(&chunk)) results += chunk.results_size();
  const grpc::Status ended = reader->Finish();
  EXPECT_EQ(ended.error_code(), StatusCode::CANCELLED) << ended.error_message();
  EXPECT_LT(results, 20000);
  EXPECT_NE(rig_.log().find("its client read nothing for 1 s"), std::string::npos) << rig_.log();
  op.Stop();
}

TEST_F(StreamGateTest, TheDocumentedCapsAreTheServers) {
  Start("");
  const std::string id = QueuedSession();
  ASSERT_FALSE(id.empty());
  // page_size: larger values are served as 1,000, never refused.
  v1::ListSessionsRequest list;
  list.set_page_size(1001);
  v1::ListSessionsResponse listed;
  EXPECT_TRUE(rig_.control().ListSessions(DaemonRig::Context().get(), list, &listed).ok());
  // chunk_size: 1,024 accepted, 1,025 refused naming the field.
  auto batch_status = [&](std::uint32_t chunk_size) {
    v1::InterpolateBatchRequest batch;
    batch.set_session_id(id);
    batch.set_chunk_size(chunk_size);
    v1::IsoDirection* at = batch.add_directions()->mutable_iso();
    at->set_theta_i(30);
    at->set_theta_o(30);
    at->set_phi(10);
    auto context = DaemonRig::Context(kAnalystToken);
    auto reader = rig_.interpolation().InterpolateBatch(context.get(), batch);
    v1::InterpolateBatchChunk chunk;
    while (reader->Read(&chunk)) {
    }
    return reader->Finish();
  };
  const grpc::Status at_cap = batch_status(1024);
  EXPECT_EQ(at_cap.error_message().find("chunk_size"), std::string::npos) << at_cap.error_message();
  const grpc::Status over_cap = batch_status(1025);
  EXPECT_EQ(over_cap.error_code(), StatusCode::INVALID_ARGUMENT);
  EXPECT_NE(over_cap.error_message().find("chunk_size"), std::string::npos);
  // chunk_bytes: 4 MiB − 1 KiB accepted, one more byte refused naming the field.
  auto export_status = [&](std::uint32_t chunk_bytes) {
    v1::ExportRequest request;
    request.set_session_id(id);
    request.set_format(v1::EXPORT_FORMAT_READINGS_CSV);
    request.set_chunk_bytes(chunk_bytes);
    auto context = DaemonRig::Context(kAnalystToken);
    auto reader = rig_.data().Export(context.get(), request);
    v1::ExportChunk chunk;
    while (reader->Read(&chunk)) {
    }
    return reader->Finish();
  };
  const grpc::Status largest = export_status(4 * 1024 * 1024 - 1024);
  EXPECT_EQ(largest.error_message().find("chunk_bytes"), std::string::npos)
      << largest.error_message();
  const grpc::Status too_large = export_status(4 * 1024 * 1024 - 1023);
  EXPECT_EQ(too_large.error_code(), StatusCode::INVALID_ARGUMENT);
  EXPECT_NE(too_large.error_message().find("chunk_bytes"), std::string::npos);
}

}  // namespace
}  // namespace brdf::testing
