// brdfd's memory under clients that do not read (ctest label "load"; issue 40): InterpolateBatch
// and Export produce their answers as the client reads them, so streams left unread hold a few
// chunks each, not their whole answers, and the memory they held goes back to the system once
// they end (the allocator's trim, daemon/rpc/memory_budget.h). Beyond [server] memory_budget_mb
// new heavy calls are refused with RESOURCE_EXHAUSTED naming the key, while the control plane,
// Interpolate and the light streams go on.
//
// Figures (VmRSS of the brdfd process, this machine, 2026-12-07): 8 InterpolateBatch calls of
// 100,000 directions and 16 grid exports (4 MiB chunks asked) left unread grow brdfd by 109–115 MB
// (the exports ~60 MB of it, measured alone), and under 15 MB stays once they have ended. Before
// InterpolateBatch read its own request (daemon/api/batch_request.h) the same run grew by
// 172–190 MB, the batches alone by 105 MB: gRPC parsed each request (2.4 MB on the wire, ~13 MB
// as messages) before the call waited for its work permit. Main's brdfd before issue 40 grew by
// 276 MB and kept 84 MB (each unread export held three copies of a 4 MiB chunk, and the allocator
// kept what the streams had freed).
#include <gtest/gtest.h>

#include <chrono>
#include <fstream>
#include <string>
#include <thread>
#include <vector>

#include "tests/support/daemon/test_rig.h"
#include "tests/support/plan_fixtures.h"

namespace brdf::testing {
namespace {

using namespace std::chrono_literals;

constexpr int kUnreadBatches = 8;
constexpr int kUnreadExports = 16;
constexpr int kBatchDirections = 100000;
// Growth allowed while the streams above are held unread: ~1.8× what they take here.
constexpr long kMaxGrowthKb = 200 * 1024;
// What may stay resident once they have ended, over the baseline taken before them.
constexpr long kMaxLeftKb = 40 * 1024;

const std::string kPlan = PlanFixture("memory under unread streams")
                              .SampleRotation({30, 30, 10}, {0, 60, 5}, 10)
                              .Measurement(100, 1)
                              .Retry(3, 0);

// The daemon's configuration with `lines` added to [server].
std::string ConfigWith(DaemonRig& rig, const std::string& lines) {
  std::string toml = DaemonConfigToml(rig.sim(), rig.database());
  const std::string listen = "listen = \"127.0.0.1:0\"\n";
  toml.insert(toml.find(listen) + listen.size(), lines);
  return toml;
}

// A session with a few sample readings, then aborted (nothing records meanwhile).
std::string RecordSome(DaemonRig& rig) {
  Result<v1::Session> submitted = rig.Submit(kPlan);
  EXPECT_TRUE(submitted.ok()) << submitted.status().ToString();
  if (!submitted.ok()) return "";
  const std::string id = submitted->session_id();
  GrpcOperator op(rig, id);
  const v1::Session recording = rig.WaitFor(
      id, [](const v1::Session& s) { return s.progress().done_samples() >= 6; }, 60s);
  EXPECT_GE(recording.progress().done_samples(), 6u) << rig.log();
  v1::AbortSessionRequest abort;
  abort.set_session_id(id);
  abort.set_reason("enough readings");
  v1::AbortSessionResponse aborted;
  (void)rig.control().AbortSession(DaemonRig::Context().get(), abort, &aborted);
  rig.WaitForState(id, v1::SESSION_STATE_ABORTED);
  op.Stop();
  return id;
}

v1::InterpolateBatchRequest Batch(const std::string& id, int n) {
  v1::InterpolateBatchRequest r;
  r.set_session_id(id);
  r.set_chunk_size(1024);
  for (int d = 0; d < n; ++d) {
    v1::IsoDirection* at = r.add_directions()->mutable_iso();
    at->set_theta_i(20 + d % 20);
    at->set_theta_o(10 + (d / 20) % 60);
    at->set_phi(d % 180);
  }
  return r;
}

v1::ExportRequest GridExport(const std::string& id) {
  v1::ExportRequest r;
  r.set_session_id(id);
  r.set_format(v1::EXPORT_FORMAT_GRID_NPY);
  r.set_step_theta_i(5);
  r.set_step_theta_o(5);
  r.set_step_phi(10);
  r.set_chunk_bytes(4 * 1024 * 1024 - 1024);
  r.set_fill(v1::EXPORT_FILL_NONE);  // a few readings on one plane: no Delaunay fallback
  return r;
}

// A channel of its own without BDP probing: an unread stream's window stays at 64 KiB.
std::shared_ptr<grpc::Channel> Channel(DaemonRig& rig, int index) {
  grpc::ChannelArguments args;
  args.SetInt("brdf.test.connection", index);
  args.SetInt(GRPC_ARG_HTTP2_BDP_PROBE, 0);
  args.SetMaxReceiveMessageSize(64 * 1024 * 1024);
  return grpc::CreateCustomChannel(rig.daemon()->address(), grpc::InsecureChannelCredentials(),
                                   args);
}

TEST(MemoryBoundTest, UnreadBatchesAndExportsHoldLittleAndTheirMemoryGoesBack) {
  DaemonRig rig;
  Status st = rig.StartSim();
  ASSERT_TRUE(st.ok()) << st.ToString();
  st = rig.StartDaemon(
      ConfigWith(rig, "max_streams_per_token = 200\nstream_stall_timeout_s = 600\n"));
  ASSERT_TRUE(st.ok()) << st.ToString();
  const std::string id = RecordSome(rig);
  ASSERT_FALSE(id.empty());
  const pid_t pid = rig.daemon()->pid();

  // Warm-up: one of each read to its end (the index built, the code paths and pools touched).
  auto read_channel = Channel(rig, 0);
  {
    auto context = DaemonRig::Context(kAnalystToken, 60s);
    auto batch = v1::Interpolation::NewStub(read_channel)
                     ->InterpolateBatch(context.get(), Batch(id, kBatchDirections));
    v1::InterpolateBatchChunk chunk;
    int results = 0;
    while (batch->Read(&chunk)) results += chunk.results_size();
    ASSERT_TRUE(batch->Finish().ok());
    EXPECT_EQ(results, kBatchDirections);
    auto export_context = DaemonRig::Context(kAnalystToken, 60s);
    auto exported = v1::Data::NewStub(read_channel)->Export(export_context.get(), GridExport(id));
    v1::ExportChunk piece;
    while (exported->Read(&piece)) {
    }
    const grpc::Status done = exported->Finish();
    ASSERT_TRUE(done.ok()) << done.error_message();
  }
  std::this_thread::sleep_for(3s);  // the trim after streams end runs within about a second
  const long baseline = ResidentKb(pid);
  ASSERT_GT(baseline, 0);

  // The streams, never read.
  std::vector<std::shared_ptr<grpc::Channel>> channels;
  for (int c = 1; c <= 4; ++c) channels.push_back(Channel(rig, c));
  std::vector<std::unique_ptr<grpc::ClientContext>> contexts;
  std::vector<std::unique_ptr<grpc::ClientReaderInterface<v1::InterpolateBatchChunk>>> batches;
  std::vector<std::unique_ptr<grpc::ClientReaderInterface<v1::ExportChunk>>> exports;
  const v1::InterpolateBatchRequest batch = Batch(id, kBatchDirections);
  for (int i = 0; i < kUnreadBatches + kUnreadExports; ++i) {
    const auto& channel = channels[static_cast<std::size_t>(i) % channels.size()];
    contexts.push_back(DaemonRig::Context(kAnalystToken, 120s));
    if (i < kUnreadBatches) {
      batches.push_back(
          v1::Interpolation::NewStub(channel)->InterpolateBatch(contexts.back().get(), batch));
    } else {
      exports.push_back(v1::Data::NewStub(channel)->Export(contexts.back().get(), GridExport(id)));
    }
  }
  long peak = baseline;
  for (int i = 0; i < 60; ++i) {  // 6 s: every stream computes up to its first blocked write
    peak = std::max(peak, ResidentKb(pid));
    std::this_thread::sleep_for(100ms);
  }
  // The control plane answers meanwhile.
  v1::RigStatus status;
  const grpc::Status rig_status =
      rig.control().GetRigStatus(DaemonRig::Context(kOperatorToken).get(), {}, &status);
  EXPECT_TRUE(rig_status.ok()) << rig_status.error_message();

  for (auto& context : contexts) context->TryCancel();
  for (auto& b : batches) (void)b->Finish();
  for (auto& e : exports) (void)e->Finish();
  batches.clear();
  exports.clear();
  std::this_thread::sleep_for(4s);
  const long after = ResidentKb(pid);
  std::printf(
      "brdfd VmRSS: baseline %ld kB, peak with %d batches and %d exports unread %ld kB "
      "(+%ld), %ld kB after they ended (+%ld)\n",
      baseline, kUnreadBatches, kUnreadExports, peak, peak - baseline, after, after - baseline);
  EXPECT_LT(peak - baseline, kMaxGrowthKb) << "unread streams hold more than a few chunks each";
  EXPECT_LT(after - baseline, kMaxLeftKb) << "memory freed by the streams stayed with brdfd";
}

TEST(MemoryBoundTest, HeavyCallsBeyondTheBudgetAreRefusedNamingTheKeyWhileTheRestGoesOn) {
  DaemonRig rig;
  Status st = rig.StartSim();
  ASSERT_TRUE(st.ok()) << st.ToString();
  // 16 MB, the least the key takes: brdfd's own resident memory is beyond it from the start.
  st = rig.StartDaemon(ConfigWith(rig, "memory_budget_mb = 16\n"));
  ASSERT_TRUE(st.ok()) << st.ToString();
  const std::string id = RecordSome(rig);
  ASSERT_FALSE(id.empty());

  auto batch_context = DaemonRig::Context(kAnalystToken);
  auto batch = rig.interpolation().InterpolateBatch(batch_context.get(), Batch(id, 10));
  v1::InterpolateBatchChunk chunk;
  EXPECT_FALSE(batch->Read(&chunk));
  const grpc::Status refused_batch = batch->Finish();
  EXPECT_EQ(refused_batch.error_code(), grpc::StatusCode::RESOURCE_EXHAUSTED);
  EXPECT_NE(refused_batch.error_message().find("memory_budget_mb"), std::string::npos)
      << refused_batch.error_message();
  EXPECT_NE(refused_batch.error_message().find("InterpolateBatch"), std::string::npos)
      << refused_batch.error_message();

  auto export_context = DaemonRig::Context(kAnalystToken);
  v1::ExportRequest csv;
  csv.set_session_id(id);
  csv.set_format(v1::EXPORT_FORMAT_READINGS_CSV);
  auto exported = rig.data().Export(export_context.get(), csv);
  v1::ExportChunk piece;
  EXPECT_FALSE(exported->Read(&piece));
  const grpc::Status refused_export = exported->Finish();
  EXPECT_EQ(refused_export.error_code(), grpc::StatusCode::RESOURCE_EXHAUSTED);
  EXPECT_NE(refused_export.error_message().find("[server] memory_budget_mb"), std::string::npos)
      << refused_export.error_message();

  // The light calls are not the budget's: Interpolate, a readings stream and the control plane.
  v1::InterpolateRequest one;
  one.set_session_id(id);
  one.mutable_direction()->mutable_iso()->set_theta_i(30);
  one.mutable_direction()->mutable_iso()->set_theta_o(30);
  one.mutable_direction()->mutable_iso()->set_phi(10);
  v1::InterpolateResponse answer;
  const grpc::Status interpolated =
      rig.interpolation().Interpolate(DaemonRig::Context(kAnalystToken).get(), one, &answer);
  EXPECT_TRUE(interpolated.ok()) << interpolated.error_message();
  Result<std::vector<v1::Reading>> readings = rig.Readings(id);
  ASSERT_TRUE(readings.ok()) << readings.status().ToString();
  EXPECT_FALSE(readings->empty());
  v1::RigStatus status;
  const grpc::Status rig_status =
      rig.control().GetRigStatus(DaemonRig::Context(kOperatorToken).get(), {}, &status);
  EXPECT_TRUE(rig_status.ok()) << rig_status.error_message();
}

}  // namespace
}  // namespace brdf::testing
