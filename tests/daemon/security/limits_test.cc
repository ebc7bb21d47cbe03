// Hostile input on every RPC: malformed and deeply nested wire messages, oversize requests, bad
// and unknown session ids (enumerated from brdf.proto's descriptor, so a new RPC is covered), then
// per RPC NaN and infinities, out-of-range angles, empty and huge batches, oversize plans, bad
// enums and pages. Each must get a precise error (the code, and the field named in the message),
// never a crash: the daemon answers afterwards and exits 0 on SIGTERM. Plan JSON nesting
// (core/plan) is checked in process. The limits are service_common.h's.
#include <gtest/gtest.h>

#include <chrono>
#include <cmath>
#include <limits>
#include <set>

#include "core/plan/plan_json.h"
#include "daemon/api/common.h"
#include "tests/support/daemon/raw_call.h"
#include "tests/support/daemon/test_rig.h"
#include "tests/support/plan_fixtures.h"

namespace brdf::testing {
namespace {

using namespace std::chrono_literals;
using google::protobuf::MethodDescriptor;
using grpc::StatusCode;

constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();
constexpr double kInf = std::numeric_limits<double>::infinity();
const std::string kOperatorHeader = std::string("Bearer ") + kOperatorToken;

const std::string kSmallPlan = plans::OnePose();

// Protobuf wire format: a varint, and an unknown field number no message of ours uses.
std::string Varint(std::uint64_t v) {
  std::string out;
  while (v >= 0x80) {
    out.push_back(static_cast<char>((v & 0x7f) | 0x80));
    v >>= 7;
  }
  out.push_back(static_cast<char>(v));
  return out;
}
constexpr std::uint64_t kUnknownField = 1000;
std::string Tag(std::uint64_t field, int wire_type) {
  return Varint((field << 3) | static_cast<std::uint64_t>(wire_type));
}

// `depth` groups nested in one another (start-group … end-group), as unknown fields.
std::string NestedGroups(int depth) {
  std::string out;
  for (int i = 0; i < depth; ++i) out += Tag(kUnknownField, 3);
  for (int i = 0; i < depth; ++i) out += Tag(kUnknownField, 4);
  return out;
}

// An unknown length-delimited field of `bytes` bytes.
std::string UnknownBytes(std::size_t bytes) {
  return Tag(kUnknownField, 2) + Varint(bytes) + std::string(bytes, 'x');
}

void ExpectCode(const grpc::Status& st, StatusCode code, const std::string& mention,
                const std::string& what) {
  EXPECT_EQ(st.error_code(), code) << what << ": " << st.error_message();
  EXPECT_NE(st.error_message().find(mention), std::string::npos)
      << what << ": \"" << st.error_message() << "\" does not mention " << mention;
  // Errors stay small whatever was sent (they travel in a trailer).
  EXPECT_LT(st.error_message().size(), 2000u) << what;
}

class LimitsTest : public ::testing::Test {
 protected:
  void SetUp() override {
    Result<int> port = FreeTcpPort();
    ASSERT_TRUE(port.ok());
    Status st = rig_.StartDaemon(AbsentDevicesToml(rig_.database(), *port));
    ASSERT_TRUE(st.ok()) << st.ToString();
    Result<v1::Session> queued = rig_.Submit(kSmallPlan, /*start_now=*/false);
    ASSERT_TRUE(queued.ok()) << queued.status().ToString();
    id_ = queued->session_id();
  }
  void TearDown() override {
    if (rig_.daemon() != nullptr) {
      // Still answering, the session untouched, and a clean exit: nothing crashed.
      Result<v1::Session> session = rig_.Get(id_);
      EXPECT_TRUE(session.ok()) << session.status().ToString();
      if (session.ok()) {
        EXPECT_EQ(session->state(), v1::SESSION_STATE_QUEUED);
      }
      Result<int> code = rig_.StopDaemon();
      EXPECT_TRUE(code.ok() && *code == 0)
          << (code.ok() ? "exit code " + std::to_string(*code) : code.status().ToString());
    }
    if (HasFailure()) std::cerr << "---- brdfd log ----\n" << rig_.log() << "\n----\n";
  }

  static std::unique_ptr<grpc::ClientContext> Ctx() {
    return DaemonRig::Context(kOperatorToken, 60s);
  }

  grpc::Status Batch(const v1::InterpolateBatchRequest& request) {
    auto ctx = Ctx();
    auto reader = rig_.interpolation().InterpolateBatch(ctx.get(), request);
    v1::InterpolateBatchChunk chunk;
    while (reader->Read(&chunk)) {
    }
    return reader->Finish();
  }

  grpc::Status Submit(const v1::Plan& plan) {
    v1::SubmitPlanRequest request;
    *request.mutable_plan() = plan;
    v1::SubmitPlanResponse response;
    return rig_.control().SubmitPlan(Ctx().get(), request, &response);
  }

  // ValidatePlan's problems as "<path>: <message>" lines.
  std::string Problems(const v1::Plan& plan, bool* valid) {
    v1::ValidatePlanRequest request;
    *request.mutable_plan() = plan;
    v1::ValidatePlanResponse response;
    grpc::Status st = rig_.control().ValidatePlan(Ctx().get(), request, &response);
    EXPECT_TRUE(st.ok()) << st.error_message();
    *valid = response.valid();
    std::string out;
    for (const auto& p : response.problems()) out += p.field_path() + ": " + p.message() + "\n";
    return out;
  }

  DaemonRig rig_;
  std::string id_;
};

TEST(PlanJsonLimitsTest, DeepNestingIsRefusedWithoutOverflowingTheStack) {
  for (int depth : {10000, 1000000}) {
    for (const std::string& open : {std::string("["), std::string("{\"name\":")}) {
      std::string json;
      for (int i = 0; i < depth; ++i) json += open;
      Result<v1::Plan> plan = plan::ParsePlanJson(json);
      EXPECT_FALSE(plan.ok()) << depth << " × " << open;
      if (!plan.ok()) {
        EXPECT_EQ(plan.status().code(), brdf::StatusCode::kInvalidArgument);
      }
    }
  }
  // Balanced, deeply nested arrays inside a repeated field: protobuf's parser flattens them
  // (no stack overflow); whatever it makes of them holds no pose.
  std::string json = "{\"poseList\": {\"poses\": ";
  json += std::string(100000, '[') + std::string(100000, ']') + "}}";
  Result<v1::Plan> nested = plan::ParsePlanJson(json);
  if (nested.ok()) {
    EXPECT_EQ(nested->pose_list().poses_size(), 0);
  }
  // Larger than the cap: refused unread, saying so.
  Result<v1::Plan> huge = plan::ParsePlanJson(std::string(plan::kMaxPlanJsonBytes + 1, ' '));
  ASSERT_FALSE(huge.ok());
  EXPECT_NE(huge.status().message().find("cap"), std::string::npos) << huge.status().message();
}

TEST_F(LimitsTest, EveryRpcSurvivesMalformedNestedAndOversizeWireMessages) {
  struct Case {
    std::string what;
    std::string bytes;
  };
  const std::vector<Case> cases = {
      {"garbage bytes", std::string("\xff\xff\xff\xff\xff\xff\xff\xff\xff\xff\x01", 11)},
      {"a truncated field", Tag(1, 2) + Varint(1000) + "short"},
      {"10,000 nested groups", NestedGroups(10000)},
      {"200,000 nested groups", NestedGroups(200000)},
      {"a session id that is not UTF-8", Tag(1, 2) + Varint(2) + "\xff\xfe"},
      {"an unterminated group", std::string(10000, '\0').replace(0, 2, Tag(kUnknownField, 3))},
  };
  for (const MethodDescriptor* method : AllMethods()) {
    for (const Case& c : cases) {
      RawReply reply = CallRaw(rig_.channel(), PathOf(*method), c.bytes, kOperatorHeader, 30s, 1);
      // gRPC refuses a request it cannot parse before our code sees it.
      EXPECT_NE(reply.status.error_code(), StatusCode::OK) << method->full_name() << ": " << c.what;
      EXPECT_NE(reply.status.error_code(), StatusCode::UNAVAILABLE)
          << method->full_name() << ": " << c.what << " (did the daemon die?) "
          << reply.status.error_message();
    }
    // Larger than the server's receive limit: RESOURCE_EXHAUSTED from the transport.
    RawReply reply =
        CallRaw(rig_.channel(), PathOf(*method), UnknownBytes(daemon::kMaxReceiveMessageBytes + 1),
                kOperatorHeader, 60s, 1);
    EXPECT_EQ(reply.status.error_code(), StatusCode::RESOURCE_EXHAUSTED)
        << method->full_name() << ": " << reply.status.error_message();
  }
  v1::RigStatus status;
  grpc::Status st = rig_.control().GetRigStatus(Ctx().get(), {}, &status);
  EXPECT_TRUE(st.ok()) << st.error_message();
}

TEST_F(LimitsTest, EveryRpcWithASessionIdRefusesBadOnesAndNamesUnknownOnes) {
  const std::string nul_inside(
      "7\0"
      "1",
      3);
  const std::vector<std::string> bad = {"",
                                        "abc",
                                        "-1",
                                        "0",
                                        "1e3",
                                        " 7",
                                        "7 ",
                                        "0x10",
                                        "99999999999999999999999",
                                        nul_inside,
                                        std::string(1024 * 1024, '9')};
  int checked = 0;
  for (const MethodDescriptor* method : AllMethods()) {
    if (method->input_type()->FindFieldByName("session_id") == nullptr) continue;
    ++checked;
    for (const std::string& id : bad) {
      RawReply reply =
          CallRaw(rig_.channel(), PathOf(*method), RequestBytes(*method, id), kOperatorHeader);
      const std::string what = method->full_name() + " with session_id of " +
                               std::to_string(id.size()) + " bytes \"" + id.substr(0, 30) + "\"";
      // An empty request is refused for its first bad field; the id must be among what is named
      // when it is set (and non-empty).
      EXPECT_EQ(reply.status.error_code(), StatusCode::INVALID_ARGUMENT)
          << what << ": " << reply.status.error_message();
      EXPECT_LT(reply.status.error_message().size(), 2000u) << what;
      EXPECT_EQ(reply.messages, 0) << what;
    }
  }
  EXPECT_GE(checked, 8);  // the control verbs, watch, readings, interpolation, export

  // Unknown ids, with valid arguments otherwise: NOT_FOUND naming the id.
  const std::string unknown = "987654321";
  auto ctx = [] { return Ctx(); };
  v1::StartSessionRequest start;
  start.set_session_id(unknown);
  v1::StartSessionResponse started;
  ExpectCode(rig_.control().StartSession(ctx().get(), start, &started), StatusCode::NOT_FOUND,
             unknown, "StartSession");
  v1::PauseSessionRequest pause;
  pause.set_session_id(unknown);
  v1::PauseSessionResponse paused;
  ExpectCode(rig_.control().PauseSession(ctx().get(), pause, &paused), StatusCode::NOT_FOUND,
             unknown, "PauseSession");
  v1::ResumeSessionRequest resume;
  resume.set_session_id(unknown);
  v1::ResumeSessionResponse resumed;
  ExpectCode(rig_.control().ResumeSession(ctx().get(), resume, &resumed), StatusCode::NOT_FOUND,
             unknown, "ResumeSession");
  v1::AbortSessionRequest abort;
  abort.set_session_id(unknown);
  v1::AbortSessionResponse aborted;
  ExpectCode(rig_.control().AbortSession(ctx().get(), abort, &aborted), StatusCode::NOT_FOUND,
             unknown, "AbortSession");
  v1::AnswerPromptRequest answer;
  answer.set_session_id(unknown);
  v1::AnswerPromptResponse answered;
  ExpectCode(rig_.control().AnswerPrompt(ctx().get(), answer, &answered), StatusCode::NOT_FOUND,
             unknown, "AnswerPrompt");
  v1::GetSessionRequest get;
  get.set_session_id(unknown);
  v1::Session session;
  ExpectCode(rig_.control().GetSession(ctx().get(), get, &session), StatusCode::NOT_FOUND, unknown,
             "GetSession");
  {
    v1::WatchSessionRequest watch;
    watch.set_session_id(unknown);
    auto c = ctx();
    auto reader = rig_.control().WatchSession(c.get(), watch);
    v1::SessionEvent event;
    EXPECT_FALSE(reader->Read(&event));
    ExpectCode(reader->Finish(), StatusCode::NOT_FOUND, unknown, "WatchSession");
  }
  {
    v1::StreamReadingsRequest readings;
    readings.set_session_id(unknown);
    auto c = ctx();
    auto reader = rig_.data().StreamReadings(c.get(), readings);
    v1::Reading reading;
    EXPECT_FALSE(reader->Read(&reading));
    ExpectCode(reader->Finish(), StatusCode::NOT_FOUND, unknown, "StreamReadings");
  }
  v1::InterpolateRequest interpolate;
  interpolate.set_session_id(unknown);
  interpolate.mutable_direction()->mutable_iso()->set_theta_i(10);
  v1::InterpolateResponse interpolated;
  ExpectCode(rig_.interpolation().Interpolate(ctx().get(), interpolate, &interpolated),
             StatusCode::NOT_FOUND, unknown, "Interpolate");
  v1::InterpolateBatchRequest batch;
  batch.set_session_id(unknown);
  batch.add_directions()->mutable_iso()->set_theta_i(10);
  ExpectCode(Batch(batch), StatusCode::NOT_FOUND, unknown, "InterpolateBatch");
}

TEST_F(LimitsTest, InterpolateRefusesNonFiniteAndOutOfRangeAnglesNamingTheField) {
  struct Angle {
    std::string field;
    std::function<void(v1::DirectionQuery&, double)> set;
    double too_low, too_high;
  };
  const std::vector<Angle> angles = {
      {"iso.theta_i", [](v1::DirectionQuery& q, double v) { q.mutable_iso()->set_theta_i(v); },
       -0.001, 90.001},
      {"iso.theta_o", [](v1::DirectionQuery& q, double v) { q.mutable_iso()->set_theta_o(v); },
       -0.001, 90.001},
      {"iso.phi", [](v1::DirectionQuery& q, double v) { q.mutable_iso()->set_phi(v); }, -1e6, 1e6},
      {"four.theta_i", [](v1::DirectionQuery& q, double v) { q.mutable_four()->set_theta_i(v); },
       -0.001, 90.001},
      {"four.phi_i", [](v1::DirectionQuery& q, double v) { q.mutable_four()->set_phi_i(v); }, -1e6,
       1e6},
      {"four.theta_o", [](v1::DirectionQuery& q, double v) { q.mutable_four()->set_theta_o(v); },
       -0.001, 90.001},
      {"four.phi_o", [](v1::DirectionQuery& q, double v) { q.mutable_four()->set_phi_o(v); }, -1e6,
       1e6},
  };
  for (const Angle& a : angles) {
    for (double v : {kNaN, kInf, -kInf, a.too_low, a.too_high, 1e308, -1e308}) {
      v1::InterpolateRequest request;
      request.set_session_id(id_);
      v1::DirectionQuery* q = request.mutable_direction();
      if (a.field.rfind("iso", 0) == 0) {
        q->mutable_iso()->set_theta_i(10);
      } else {
        q->mutable_four()->set_theta_i(10);
      }
      a.set(*q, v);
      v1::InterpolateResponse response;
      ExpectCode(rig_.interpolation().Interpolate(Ctx().get(), request, &response),
                 StatusCode::INVALID_ARGUMENT, "direction." + a.field,
                 "Interpolate " + a.field + " = " + std::to_string(v));
      // The same at index 7 of a batch.
      v1::InterpolateBatchRequest batch;
      batch.set_session_id(id_);
      for (int i = 0; i < 10; ++i) batch.add_directions()->mutable_iso()->set_theta_i(10);
      *batch.mutable_directions(7) = request.direction();
      ExpectCode(Batch(batch), StatusCode::INVALID_ARGUMENT, "directions[7]." + a.field,
                 "InterpolateBatch " + a.field + " = " + std::to_string(v));
    }
  }
  // Options and enums.
  v1::InterpolateRequest request;
  request.set_session_id(id_);
  request.mutable_direction()->mutable_iso()->set_theta_i(10);
  v1::InterpolateResponse response;
  for (double scale : {kNaN, kInf, -1.0, 0.0}) {
    request.mutable_options()->clear_axis_scale();
    request.mutable_options()->add_axis_scale(scale);
    ExpectCode(rig_.interpolation().Interpolate(Ctx().get(), request, &response),
               StatusCode::INVALID_ARGUMENT, "options.axis_scale[0]",
               "axis_scale " + std::to_string(scale));
  }
  request.mutable_options()->clear_axis_scale();
  for (int i = 0; i < 100; ++i) request.mutable_options()->add_axis_scale(1);
  ExpectCode(rig_.interpolation().Interpolate(Ctx().get(), request, &response),
             StatusCode::INVALID_ARGUMENT, "options.axis_scale", "100 axis scales");
  request.clear_options();
  request.set_method(static_cast<v1::InterpolationMethod>(-3));
  ExpectCode(rig_.interpolation().Interpolate(Ctx().get(), request, &response),
             StatusCode::INVALID_ARGUMENT, "method", "method -3");
  request.set_method(v1::INTERPOLATION_METHOD_UNSPECIFIED);
  request.set_quantity(static_cast<v1::Quantity>(1 << 20));
  ExpectCode(rig_.interpolation().Interpolate(Ctx().get(), request, &response),
             StatusCode::INVALID_ARGUMENT, "quantity", "quantity 2^20");
}

TEST_F(LimitsTest, BatchesAreBoundedAtBothEnds) {
  v1::InterpolateBatchRequest request;
  request.set_session_id(id_);
  ExpectCode(Batch(request), StatusCode::INVALID_ARGUMENT, "directions", "empty batch");
  // Exactly the limit passes the checks (and then finds no reading in the queued session).
  for (int i = 0; i < daemon::kMaxBatchDirections; ++i) {
    request.add_directions()->mutable_iso()->set_theta_i(i % 90);
  }
  grpc::Status st = Batch(request);
  EXPECT_EQ(st.error_code(), StatusCode::FAILED_PRECONDITION) << st.error_message();
  request.add_directions()->mutable_iso()->set_theta_i(1);
  st = Batch(request);
  // (service_interpolation.cc answers RESOURCE_EXHAUSTED; INVALID_ARGUMENT would do as well.)
  EXPECT_TRUE(st.error_code() == StatusCode::RESOURCE_EXHAUSTED ||
              st.error_code() == StatusCode::INVALID_ARGUMENT)
      << st.error_code() << " " << st.error_message();
  EXPECT_NE(st.error_message().find(std::to_string(daemon::kMaxBatchDirections)), std::string::npos)
      << st.error_message();
  // Larger than a message may be: the transport refuses it.
  request.clear_directions();
  v1::DirectionQuery four;
  four.mutable_four()->set_theta_i(1.5);
  four.mutable_four()->set_phi_i(-2.5);
  four.mutable_four()->set_theta_o(3.5);
  four.mutable_four()->set_phi_o(4.5);
  while (request.ByteSizeLong() <= static_cast<std::size_t>(daemon::kMaxReceiveMessageBytes)) {
    for (int i = 0; i < 10000; ++i) *request.add_directions() = four;
  }
  EXPECT_EQ(Batch(request).error_code(), StatusCode::RESOURCE_EXHAUSTED);
  // Chunk sizes.
  request.clear_directions();
  request.add_directions()->mutable_iso()->set_theta_i(1);
  request.set_chunk_size(daemon::kMaxChunkSize + 1);
  ExpectCode(Batch(request), StatusCode::INVALID_ARGUMENT, "chunk_size", "chunk_size over");
  request.set_chunk_size(0xffffffffu);
  ExpectCode(Batch(request), StatusCode::INVALID_ARGUMENT, "chunk_size", "chunk_size 2^32-1");
  request.set_chunk_size(daemon::kMaxChunkSize);
  EXPECT_EQ(Batch(request).error_code(), StatusCode::FAILED_PRECONDITION);
}

TEST_F(LimitsTest, HostilePlansAreRefusedWithTheirFieldAndNothingIsStored) {
  struct Case {
    std::string what;
    v1::Plan plan;
    std::string mention;
  };
  std::vector<Case> cases;
  for (double v : {kNaN, kInf, -kInf, 1e308, -720.0}) {
    for (const std::string& axis :
         {std::string("alpha"), std::string("beta"), std::string("delta")}) {
      v1::Plan plan;
      plan.set_name("hostile");
      v1::PoseEntry* pose = plan.mutable_pose_list()->add_poses();
      pose->set_alpha(0);
      pose->set_beta(10);
      pose->set_delta(40);
      if (axis == "alpha") pose->set_alpha(v);
      if (axis == "beta") pose->set_beta(v);
      if (axis == "delta") pose->set_delta(v);
      cases.push_back(
          {"pose " + axis + " = " + std::to_string(v), plan, "poseList.poses[0]." + axis});
    }
  }
  for (double step : {kNaN, kInf, 0.0, -5.0, 1e-9}) {
    v1::Plan plan;
    plan.set_name("hostile sweep");
    plan.mutable_sample_rotation()->mutable_alpha()->set_start(0);
    plan.mutable_sample_rotation()->mutable_alpha()->set_stop(80);
    plan.mutable_sample_rotation()->mutable_alpha()->set_step(step);
    plan.mutable_sample_rotation()->mutable_delta()->set_start(30);
    plan.mutable_sample_rotation()->mutable_delta()->set_stop(30);
    plan.mutable_sample_rotation()->mutable_delta()->set_step(10);
    cases.push_back({"alpha step " + std::to_string(step), plan, "sampleRotation.alpha"});
  }
  {
    v1::Plan plan;
    plan.set_name(std::string(1024 * 1024, 'n'));
    plan.mutable_pose_list()->add_poses()->set_delta(40);
    cases.push_back({"a 1 MiB name", plan, "name"});
  }
  {
    v1::Plan plan;
    plan.set_name("sample fixed");
    v1::DirectionTarget* target = plan.mutable_sample_fixed()->add_targets();
    target->set_theta_i(kNaN);
    target->set_theta_o(45);
    cases.push_back({"a NaN target", plan, "sampleFixed.targets[0].thetaI"});
  }
  {
    // More poses than a plan may have steps: ~7 MB, under the message limit.
    v1::Plan plan;
    plan.set_name("too many poses");
    for (int i = 0; i < 250000; ++i) {
      v1::PoseEntry* pose = plan.mutable_pose_list()->add_poses();
      pose->set_alpha(i % 80);
      pose->set_beta(i % 170);
      pose->set_delta(40);
    }
    cases.push_back({"250,000 poses", plan, "200000"});
  }
  for (const Case& c : cases) {
    const auto started = std::chrono::steady_clock::now();
    ExpectCode(Submit(c.plan), StatusCode::INVALID_ARGUMENT, c.mention, "SubmitPlan " + c.what);
    bool valid = true;
    const std::string problems = Problems(c.plan, &valid);
    EXPECT_FALSE(valid) << c.what;
    EXPECT_NE(problems.find(c.mention), std::string::npos) << c.what << ":\n" << problems;
    // Refused by counting, not by expanding without bound (a generous bound for a loaded box).
    EXPECT_LT(std::chrono::steady_clock::now() - started, 30s) << c.what;
  }
  v1::ListSessionsResponse listed;
  ASSERT_TRUE(rig_.control().ListSessions(Ctx().get(), {}, &listed).ok());
  EXPECT_EQ(listed.sessions_size(), 1);  // only the fixture's queued session
}

TEST_F(LimitsTest, VerbsPagesAndStreamsRefuseOutOfRangeArguments) {
  v1::PauseSessionRequest pause;
  pause.set_session_id(id_);
  v1::PauseSessionResponse paused;
  for (int mode : {-1, 3, std::numeric_limits<int>::max()}) {
    pause.set_mode(static_cast<v1::PauseMode>(mode));
    ExpectCode(rig_.control().PauseSession(Ctx().get(), pause, &paused),
               StatusCode::INVALID_ARGUMENT, "mode", "pause mode " + std::to_string(mode));
  }
  v1::AnswerPromptRequest answer;
  answer.set_session_id(id_);
  v1::AnswerPromptResponse answered;
  answer.set_step_index(std::numeric_limits<int>::min());
  ExpectCode(rig_.control().AnswerPrompt(Ctx().get(), answer, &answered),
             StatusCode::INVALID_ARGUMENT, "step_index", "step_index INT_MIN");
  answer.set_step_index(std::numeric_limits<int>::max());
  EXPECT_EQ(rig_.control().AnswerPrompt(Ctx().get(), answer, &answered).error_code(),
            StatusCode::FAILED_PRECONDITION);
  answer.set_step_index(0);
  answer.set_note(std::string(daemon::kMaxNoteBytes + 1, 'n'));
  ExpectCode(rig_.control().AnswerPrompt(Ctx().get(), answer, &answered),
             StatusCode::INVALID_ARGUMENT, "note", "oversize note");
  v1::AbortSessionRequest abort;
  abort.set_session_id(id_);
  abort.set_reason(std::string(daemon::kMaxNoteBytes + 1, 'r'));
  v1::AbortSessionResponse aborted;
  ExpectCode(rig_.control().AbortSession(Ctx().get(), abort, &aborted),
             StatusCode::INVALID_ARGUMENT, "reason", "oversize reason");

  v1::ListSessionsRequest list;
  v1::ListSessionsResponse listed;
  list.set_page_size(0xffffffffu);
  grpc::Status st = rig_.control().ListSessions(Ctx().get(), list, &listed);
  EXPECT_TRUE(st.ok()) << st.error_message();
  EXPECT_LE(listed.sessions_size(), static_cast<int>(daemon::kMaxPageSize));
  list.add_states(static_cast<v1::SessionState>(99));
  ExpectCode(rig_.control().ListSessions(Ctx().get(), list, &listed), StatusCode::INVALID_ARGUMENT,
             "states[0]", "state 99");
  list.clear_states();
  list.add_states(static_cast<v1::SessionState>(-7));
  ExpectCode(rig_.control().ListSessions(Ctx().get(), list, &listed), StatusCode::INVALID_ARGUMENT,
             "states[0]", "state -7");
  list.clear_states();
  list.set_page_token(std::string(1024 * 1024, '7'));
  ExpectCode(rig_.control().ListSessions(Ctx().get(), list, &listed), StatusCode::INVALID_ARGUMENT,
             "page_token", "1 MiB page token");

  auto readings = [&](const v1::StreamReadingsRequest& request, int* count) {
    auto ctx = Ctx();
    auto reader = rig_.data().StreamReadings(ctx.get(), request);
    v1::Reading reading;
    *count = 0;
    while (reader->Read(&reading)) ++*count;
    return reader->Finish();
  };
  v1::StreamReadingsRequest request;
  request.set_session_id(id_);
  int count = 0;
  request.set_after_id(-1);
  ExpectCode(readings(request, &count), StatusCode::INVALID_ARGUMENT, "after_id", "after_id -1");
  request.set_after_id(std::numeric_limits<std::int64_t>::max());
  st = readings(request, &count);
  EXPECT_TRUE(st.ok()) << st.error_message();
  EXPECT_EQ(count, 0);
  request.set_after_id(0);
  request.add_kinds(static_cast<v1::ReadingKind>(99));
  ExpectCode(readings(request, &count), StatusCode::INVALID_ARGUMENT, "kinds[0]", "kind 99");
}

}  // namespace
}  // namespace brdf::testing
