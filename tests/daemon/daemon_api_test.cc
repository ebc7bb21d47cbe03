// brdfd's API surface without a rig: start-up without devices, configuration errors, the health
// service and reflection, authentication and roles, and argument checking. brdfd runs as a
// process; its devices point at a serial port that does not exist and a closed TCP port.
#include <google/protobuf/wrappers.pb.h>
#include <grpcpp/generic/generic_stub.h>
#include <gtest/gtest.h>
#include <sched.h>
#include <unistd.h>

#include <chrono>
#include <cmath>
#include <cstdlib>
#include <fstream>
#include <future>
#include <limits>
#include <sstream>
#include <thread>

#include "core/plan/plan_json.h"
#include "tests/support/daemon/rig_teardown.h"
#include "tests/support/daemon/test_rig.h"
#include "tests/support/daemon/test_util.h"
#include "tests/support/plan_fixtures.h"

namespace brdf::testing {
namespace {

using namespace std::chrono_literals;
using grpc::StatusCode;

// A configuration whose devices are absent: no such serial port, nothing on the Modbus port.
// `server_keys`: more lines for [server].
std::string AbsentDevicesToml(const std::string& database, int dead_port,
                              const std::string& listen = "127.0.0.1:0",
                              const std::string& server_keys = "") {
  std::ostringstream t;
  t << "[server]\nlisten = \"" << listen << "\"\n"
    << server_keys << "[storage]\ndatabase = \"" << database << "\"\n"
    << "[meter]\nport = \"/dev/brdfd-test-no-such-port\"\n"
    << "[stage]\naddress = \"127.0.0.1:" << dead_port << "\"\nresponse_timeout_ms = 100\n"
    << "[[auth.tokens]]\nname = \"" << kOperatorName << "\"\ntoken = \"" << kOperatorToken
    << "\"\nrole = \"operator\"\n"
    << "[[auth.tokens]]\nname = \"test-analyst\"\ntoken = \"" << kAnalystToken
    << "\"\nrole = \"analyst\"\n";
  return t.str();
}

const std::string kSmallPlan = plans::OnePose();

class DaemonApiTest : public ::testing::Test {
 protected:
  void SetUp() override {
    Result<int> port = FreeTcpPort();
    ASSERT_TRUE(port.ok());
    dead_port_ = *port;
    Status st = rig_.StartDaemon(AbsentDevicesToml(rig_.database(), dead_port_));
    ASSERT_TRUE(st.ok()) << st.ToString();
  }
  void TearDown() override { StopDaemonExpectingCleanExit(rig_); }

  std::string SubmitQueued() {
    Result<v1::Session> s = rig_.Submit(kSmallPlan, /*start_now=*/false);
    EXPECT_TRUE(s.ok()) << s.status().ToString();
    return s.ok() ? s->session_id() : "";
  }

  DaemonRig rig_;
  int dead_port_ = 0;
};

// grpc.health.v1.Health/Check without its generated stubs: HealthCheckRequest is
// {string service = 1} (the wire format of StringValue) and HealthCheckResponse is
// {ServingStatus status = 1} (the wire format of Int32Value; SERVING = 1).
grpc::Status HealthCheck(grpc::Channel& channel, const std::string& service, int* status) {
  grpc::TemplatedGenericStub<google::protobuf::StringValue, google::protobuf::Int32Value> stub(
      std::shared_ptr<grpc::Channel>(&channel, [](grpc::Channel*) {}));
  google::protobuf::StringValue request;
  request.set_value(service);
  google::protobuf::Int32Value response;
  grpc::ClientContext context;  // no token: health needs none
  context.set_deadline(std::chrono::system_clock::now() + 5s);
  std::promise<grpc::Status> done;
  stub.UnaryCall(&context, "/grpc.health.v1.Health/Check", grpc::StubOptions(), &request, &response,
                 [&done](grpc::Status st) { done.set_value(std::move(st)); });
  grpc::Status st = done.get_future().get();
  *status = response.value();
  return st;
}

// grpc.reflection.v1alpha.ServerReflection/ServerReflectionInfo{list_services: ""}: the raw
// reply (a ListServiceResponse holds the service names as plain strings).
Result<std::string> ReflectionListServices(grpc::Channel& channel) {
  grpc::GenericStub stub(std::shared_ptr<grpc::Channel>(&channel, [](grpc::Channel*) {}));
  grpc::CompletionQueue cq;
  grpc::ClientContext context;
  context.set_deadline(std::chrono::system_clock::now() + 5s);
  auto call = stub.PrepareCall(
      &context, "/grpc.reflection.v1alpha.ServerReflection/ServerReflectionInfo", &cq);
  auto step = [&cq](int tag) {
    void* got = nullptr;
    bool ok = false;
    return cq.Next(&got, &ok) && ok && got == reinterpret_cast<void*>(static_cast<intptr_t>(tag));
  };
  call->StartCall(reinterpret_cast<void*>(1));
  if (!step(1)) return Internal("reflection: the call did not start");
  const std::string request("\x3a\x00", 2);  // field 7 (list_services), empty string
  grpc::Slice slice(request);
  grpc::ByteBuffer out(&slice, 1);
  call->Write(out, reinterpret_cast<void*>(2));
  if (!step(2)) return Internal("reflection: the request was not sent");
  grpc::ByteBuffer in;
  call->Read(&in, reinterpret_cast<void*>(3));
  if (!step(3)) return Internal("reflection: no reply");
  call->WritesDone(reinterpret_cast<void*>(4));
  step(4);
  grpc::Status status;
  call->Finish(&status, reinterpret_cast<void*>(5));
  step(5);
  std::vector<grpc::Slice> slices;
  if (!in.Dump(&slices).ok()) return Internal("reflection: unreadable reply");
  std::string text;
  for (const auto& s : slices) text.append(reinterpret_cast<const char*>(s.begin()), s.size());
  return text;
}

// Global identity and the catalogue: a submitted session has a v4 UUID, names its rig (the host
// name when [rig] name is not configured) and carries its plan's sample block, in GetSession and
// in ListSessions (where the plan itself is left out).
TEST_F(DaemonApiTest, SessionsHaveAUuidTheRigsNameAndTheSampleBlock) {
  const std::string plan = R"({"name": "gloss", "poseList": {"poses": [{"alpha": 10, "beta": 0,
    "delta": 40}]}, "sample": {"id": "P-0042", "name": "red gloss", "material": "paint",
    "tags": ["glossy", "red"], "whiteStandardId": "RS-3 #1187", "whiteReflectance": 0.97}})";
  Result<v1::Session> a = rig_.Submit(plan, /*start_now=*/false);
  Result<v1::Session> b = rig_.Submit(plan, /*start_now=*/false);
  ASSERT_TRUE(a.ok() && b.ok()) << a.status().ToString();
  char host[256] = {};
  ASSERT_EQ(gethostname(host, sizeof host - 1), 0);
  EXPECT_EQ(a->uuid().size(), 36u) << a->uuid();
  EXPECT_EQ(a->uuid()[14], '4') << a->uuid();
  EXPECT_NE(a->uuid(), b->uuid());
  EXPECT_EQ(a->rig(), host);
  EXPECT_EQ(a->sample().id(), "P-0042");
  EXPECT_EQ(a->sample().tags_size(), 2);
  v1::ListSessionsRequest request;
  v1::ListSessionsResponse list;
  grpc::Status st = rig_.control().ListSessions(DaemonRig::Context().get(), request, &list);
  ASSERT_TRUE(st.ok()) << st.error_message();
  ASSERT_EQ(list.sessions_size(), 2);
  EXPECT_EQ(list.sessions(1).uuid(), a->uuid());
  EXPECT_EQ(list.sessions(1).sample().material(), "paint");
  EXPECT_FALSE(list.sessions(1).has_plan());
  // No [archive] configured: GetRigStatus says shipping is off.
  v1::RigStatus status;
  st = rig_.control().GetRigStatus(DaemonRig::Context().get(), {}, &status);
  ASSERT_TRUE(st.ok()) << st.error_message();
  EXPECT_EQ(status.archive().state(), v1::ARCHIVE_STATE_OFF);
}

TEST_F(DaemonApiTest, StartsWithoutDevicesAndReportsThemDisconnected) {
  v1::RigStatus status;
  grpc::Status st =
      rig_.control().GetRigStatus(DaemonRig::Context(kAnalystToken).get(), {}, &status);
  ASSERT_TRUE(st.ok()) << st.error_message();
  ASSERT_EQ(status.devices_size(), 2);
  for (const auto& d : status.devices()) {
    EXPECT_NE(d.state(), v1::CONNECTION_STATE_CONNECTED) << d.name();
  }
  EXPECT_TRUE(status.meter_serial().empty());
  // The API is up meanwhile: plans are accepted (and wait in the queue).
  EXPECT_FALSE(SubmitQueued().empty());
  int health = 0;
  ASSERT_TRUE(HealthCheck(*rig_.channel(), "", &health).ok());
  EXPECT_EQ(health, 1);  // SERVING
}

TEST_F(DaemonApiTest, HealthIsServingAndReflectionListsTheServices) {
  for (const char* service : {"", "brdf.v1.Control", "brdf.v1.Data", "brdf.v1.Interpolation"}) {
    int health = 0;
    grpc::Status st = HealthCheck(*rig_.channel(), service, &health);
    ASSERT_TRUE(st.ok()) << service << ": " << st.error_message();
    EXPECT_EQ(health, 1) << service;
  }
  int health = 0;
  EXPECT_EQ(HealthCheck(*rig_.channel(), "no.such.Service", &health).error_code(),
            StatusCode::NOT_FOUND);
  Result<std::string> services = ReflectionListServices(*rig_.channel());
  ASSERT_TRUE(services.ok()) << services.status().ToString();
  for (const char* name :
       {"brdf.v1.Control", "brdf.v1.Data", "brdf.v1.Interpolation", "grpc.health.v1.Health"}) {
    EXPECT_NE(services->find(name), std::string::npos) << name;
  }
}

TEST_F(DaemonApiTest, RefusesMissingAndWrongTokensAndAnalystsOnControlVerbs) {
  const std::string id = SubmitQueued();
  v1::RigStatus rig_status;
  // No token, a wrong token, another scheme: UNAUTHENTICATED.
  grpc::Status st = rig_.control().GetRigStatus(DaemonRig::Context("").get(), {}, &rig_status);
  EXPECT_EQ(st.error_code(), StatusCode::UNAUTHENTICATED) << st.error_message();
  st = rig_.control().GetRigStatus(DaemonRig::Context("not-a-token-of-this-daemon").get(), {},
                                   &rig_status);
  EXPECT_EQ(st.error_code(), StatusCode::UNAUTHENTICATED) << st.error_message();
  st = rig_.control().GetRigStatus(
      DaemonRig::Context(std::string(kOperatorToken).substr(0, 10)).get(), {}, &rig_status);
  EXPECT_EQ(st.error_code(), StatusCode::UNAUTHENTICATED);  // a prefix is not the token
  {
    grpc::ClientContext basic;
    basic.AddMetadata("authorization", std::string("Basic ") + kOperatorToken);
    st = rig_.control().GetRigStatus(&basic, {}, &rig_status);
    EXPECT_EQ(st.error_code(), StatusCode::UNAUTHENTICATED);
  }
  v1::InterpolateRequest interpolate;
  interpolate.set_session_id(id);
  interpolate.mutable_direction()->mutable_iso()->set_theta_i(10);
  v1::InterpolateResponse interpolated;
  st = rig_.interpolation().Interpolate(DaemonRig::Context("").get(), interpolate, &interpolated);
  EXPECT_EQ(st.error_code(), StatusCode::UNAUTHENTICATED);
  {
    v1::WatchSessionRequest watch;
    watch.set_session_id(id);
    auto context = DaemonRig::Context("");
    auto reader = rig_.control().WatchSession(context.get(), watch);
    v1::SessionEvent event;
    EXPECT_FALSE(reader->Read(&event));
    EXPECT_EQ(reader->Finish().error_code(), StatusCode::UNAUTHENTICATED);
  }

  // An analyst may read everything but controls nothing.
  const auto analyst = [] { return DaemonRig::Context(kAnalystToken); };
  v1::SubmitPlanRequest submit;
  *submit.mutable_plan() = *plan::ParsePlanJson(kSmallPlan);
  v1::SubmitPlanResponse submitted;
  st = rig_.control().SubmitPlan(analyst().get(), submit, &submitted);
  EXPECT_EQ(st.error_code(), StatusCode::PERMISSION_DENIED) << st.error_message();
  EXPECT_NE(st.error_message().find("operator"), std::string::npos) << st.error_message();
  v1::StartSessionRequest start;
  start.set_session_id(id);
  v1::StartSessionResponse started;
  EXPECT_EQ(rig_.control().StartSession(analyst().get(), start, &started).error_code(),
            StatusCode::PERMISSION_DENIED);
  v1::PauseSessionRequest pause;
  pause.set_session_id(id);
  v1::PauseSessionResponse paused;
  EXPECT_EQ(rig_.control().PauseSession(analyst().get(), pause, &paused).error_code(),
            StatusCode::PERMISSION_DENIED);
  v1::AbortSessionRequest abort;
  abort.set_session_id(id);
  v1::AbortSessionResponse aborted;
  EXPECT_EQ(rig_.control().AbortSession(analyst().get(), abort, &aborted).error_code(),
            StatusCode::PERMISSION_DENIED);
  v1::AnswerPromptRequest answer;
  answer.set_session_id(id);
  v1::AnswerPromptResponse answered;
  EXPECT_EQ(rig_.control().AnswerPrompt(analyst().get(), answer, &answered).error_code(),
            StatusCode::PERMISSION_DENIED);
  // The session is untouched by the refused verbs.
  EXPECT_EQ(rig_.Get(id)->state(), v1::SESSION_STATE_QUEUED);

  EXPECT_TRUE(rig_.control().GetRigStatus(analyst().get(), {}, &rig_status).ok());
  v1::ValidatePlanRequest validate;
  *validate.mutable_plan() = submit.plan();
  v1::ValidatePlanResponse validated;
  EXPECT_TRUE(rig_.control().ValidatePlan(analyst().get(), validate, &validated).ok());
  EXPECT_TRUE(validated.valid());
  v1::ListSessionsResponse listed;
  EXPECT_TRUE(rig_.control().ListSessions(analyst().get(), {}, &listed).ok());
  v1::GetSessionRequest get;
  get.set_session_id(id);
  v1::Session session;
  EXPECT_TRUE(rig_.control().GetSession(analyst().get(), get, &session).ok());
  // Interpolation accepts the analyst (and then finds no reading to interpolate yet).
  st = rig_.interpolation().Interpolate(analyst().get(), interpolate, &interpolated);
  EXPECT_EQ(st.error_code(), StatusCode::FAILED_PRECONDITION) << st.error_message();

  EXPECT_EQ(rig_.log().find(kOperatorToken), std::string::npos);
  EXPECT_EQ(rig_.log().find(kAnalystToken), std::string::npos);
}

TEST_F(DaemonApiTest, ChecksEveryArgumentAndNamesTheField) {
  const std::string id = SubmitQueued();
  auto context = [] { return DaemonRig::Context(kOperatorToken); };
  auto expect = [](const grpc::Status& st, StatusCode code, const std::string& mention) {
    EXPECT_EQ(st.error_code(), code) << st.error_message();
    EXPECT_NE(st.error_message().find(mention), std::string::npos)
        << "\"" << st.error_message() << "\" does not mention " << mention;
  };

  // Session ids.
  v1::GetSessionRequest get;
  v1::Session session;
  get.set_session_id("abc");
  expect(rig_.control().GetSession(context().get(), get, &session), StatusCode::INVALID_ARGUMENT,
         "session_id");
  get.set_session_id("987654");
  expect(rig_.control().GetSession(context().get(), get, &session), StatusCode::NOT_FOUND,
         "987654");
  // States: resuming a queued session is not possible now.
  v1::ResumeSessionRequest resume;
  resume.set_session_id(id);
  v1::ResumeSessionResponse resumed;
  expect(rig_.control().ResumeSession(context().get(), resume, &resumed),
         StatusCode::FAILED_PRECONDITION, "queued");
  v1::PauseSessionRequest pause;
  pause.set_session_id(id);
  pause.set_mode(static_cast<v1::PauseMode>(7));
  v1::PauseSessionResponse paused;
  expect(rig_.control().PauseSession(context().get(), pause, &paused), StatusCode::INVALID_ARGUMENT,
         "mode");
  v1::AnswerPromptRequest answer;
  answer.set_session_id(id);
  answer.set_step_index(-1);
  v1::AnswerPromptResponse answered;
  expect(rig_.control().AnswerPrompt(context().get(), answer, &answered),
         StatusCode::INVALID_ARGUMENT, "step_index");

  // Plans: every problem, each with its JSON path.
  v1::SubmitPlanRequest submit;
  *submit.mutable_plan() = *plan::ParsePlanJson(R"({
    "sampleRotation": {"alpha": {"step": -10}, "delta": {"start": 0, "stop": 200, "step": 10}}
  })");
  v1::SubmitPlanResponse submitted;
  grpc::Status st = rig_.control().SubmitPlan(context().get(), submit, &submitted);
  expect(st, StatusCode::INVALID_ARGUMENT, "sampleRotation.alpha.step");
  expect(st, StatusCode::INVALID_ARGUMENT, "sampleRotation.delta");
  v1::ValidatePlanRequest validate;
  *validate.mutable_plan() = submit.plan();
  v1::ValidatePlanResponse validated;
  ASSERT_TRUE(rig_.control().ValidatePlan(context().get(), validate, &validated).ok());
  EXPECT_FALSE(validated.valid());
  EXPECT_GE(validated.problems_size(), 2);
  v1::SubmitPlanRequest empty;
  expect(rig_.control().SubmitPlan(context().get(), empty, &submitted),
         StatusCode::INVALID_ARGUMENT, "plan");

  // Interpolation: angles, forms, enums, options, batches.
  v1::InterpolateRequest interpolate;
  interpolate.set_session_id(id);
  v1::InterpolateResponse interpolated;
  expect(rig_.interpolation().Interpolate(context().get(), interpolate, &interpolated),
         StatusCode::INVALID_ARGUMENT, "direction");
  auto* iso = interpolate.mutable_direction()->mutable_iso();
  iso->set_theta_i(std::numeric_limits<double>::quiet_NaN());
  expect(rig_.interpolation().Interpolate(context().get(), interpolate, &interpolated),
         StatusCode::INVALID_ARGUMENT, "direction.iso.theta_i");
  iso->set_theta_i(10);
  iso->set_theta_o(95);
  expect(rig_.interpolation().Interpolate(context().get(), interpolate, &interpolated),
         StatusCode::INVALID_ARGUMENT, "direction.iso.theta_o");
  iso->set_theta_o(20);
  iso->set_phi(std::numeric_limits<double>::infinity());
  expect(rig_.interpolation().Interpolate(context().get(), interpolate, &interpolated),
         StatusCode::INVALID_ARGUMENT, "direction.iso.phi");
  iso->set_phi(400);
  expect(rig_.interpolation().Interpolate(context().get(), interpolate, &interpolated),
         StatusCode::INVALID_ARGUMENT, "direction.iso.phi");
  iso->set_phi(120);
  interpolate.set_method(static_cast<v1::InterpolationMethod>(42));
  expect(rig_.interpolation().Interpolate(context().get(), interpolate, &interpolated),
         StatusCode::INVALID_ARGUMENT, "method");
  interpolate.set_method(v1::INTERPOLATION_METHOD_DELAUNAY);
  interpolate.mutable_options()->add_axis_scale(-1);
  expect(rig_.interpolation().Interpolate(context().get(), interpolate, &interpolated),
         StatusCode::INVALID_ARGUMENT, "options.axis_scale[0]");
  interpolate.clear_options();
  interpolate.set_session_id("424242");
  expect(rig_.interpolation().Interpolate(context().get(), interpolate, &interpolated),
         StatusCode::NOT_FOUND, "424242");
  interpolate.set_session_id(id);
  expect(rig_.interpolation().Interpolate(context().get(), interpolate, &interpolated),
         StatusCode::FAILED_PRECONDITION, "no sample reading");

  auto batch = [&](const v1::InterpolateBatchRequest& request) {
    auto ctx = context();
    auto reader = rig_.interpolation().InterpolateBatch(ctx.get(), request);
    v1::InterpolateBatchChunk chunk;
    while (reader->Read(&chunk)) {
    }
    return reader->Finish();
  };
  v1::InterpolateBatchRequest request;
  request.set_session_id(id);
  expect(batch(request), StatusCode::INVALID_ARGUMENT, "directions");
  for (int i = 0; i < 3; ++i) request.add_directions()->mutable_iso()->set_theta_i(10);
  request.mutable_directions(2)->mutable_iso()->set_theta_i(-1);
  expect(batch(request), StatusCode::INVALID_ARGUMENT, "directions[2].iso.theta_i");
  request.mutable_directions(2)->mutable_iso()->set_theta_i(1);
  request.set_chunk_size(5000);
  expect(batch(request), StatusCode::INVALID_ARGUMENT, "chunk_size");
  request.set_chunk_size(0);
  request.clear_directions();
  for (int i = 0; i < 100001; ++i) request.add_directions()->mutable_iso()->set_theta_i(10);
  expect(batch(request), StatusCode::RESOURCE_EXHAUSTED, "100000");

  // Oversize messages are refused by the transport (16 MiB limit).
  v1::AbortSessionRequest abort;
  abort.set_session_id(id);
  abort.set_reason(std::string(17 * 1024 * 1024, 'x'));
  v1::AbortSessionResponse aborted;
  EXPECT_EQ(rig_.control().AbortSession(context().get(), abort, &aborted).error_code(),
            StatusCode::RESOURCE_EXHAUSTED);
  abort.set_reason(std::string(5000, 'x'));
  expect(rig_.control().AbortSession(context().get(), abort, &aborted),
         StatusCode::INVALID_ARGUMENT, "reason");
  EXPECT_EQ(rig_.Get(id)->state(), v1::SESSION_STATE_QUEUED);
}

TEST_F(DaemonApiTest, ListsSessionsNewestFirstInPages) {
  const std::string a = SubmitQueued();
  const std::string b = SubmitQueued();
  const std::string c = SubmitQueued();
  v1::ListSessionsRequest request;
  request.set_page_size(2);
  v1::ListSessionsResponse page;
  ASSERT_TRUE(rig_.control().ListSessions(DaemonRig::Context().get(), request, &page).ok());
  ASSERT_EQ(page.sessions_size(), 2);
  EXPECT_EQ(page.sessions(0).session_id(), c);
  EXPECT_EQ(page.sessions(1).session_id(), b);
  EXPECT_FALSE(page.sessions(0).has_plan());
  ASSERT_FALSE(page.next_page_token().empty());
  request.set_page_token(page.next_page_token());
  ASSERT_TRUE(rig_.control().ListSessions(DaemonRig::Context().get(), request, &page).ok());
  ASSERT_EQ(page.sessions_size(), 1);
  EXPECT_EQ(page.sessions(0).session_id(), a);
  EXPECT_TRUE(page.next_page_token().empty());
  request.Clear();
  request.add_states(v1::SESSION_STATE_RUNNING);
  ASSERT_TRUE(rig_.control().ListSessions(DaemonRig::Context().get(), request, &page).ok());
  EXPECT_EQ(page.sessions_size(), 0);
  request.set_page_token("garbage");
  EXPECT_EQ(rig_.control().ListSessions(DaemonRig::Context().get(), request, &page).error_code(),
            StatusCode::INVALID_ARGUMENT);
}

TEST(DaemonConfigTest, BadConfigurationExitsTwoNamingTheKeyAndTheReason) {
  TempDir dir("brdfd-config");
  const std::string path = dir.file("bad.toml").string();
  {
    std::ofstream out(path);
    out << "[server]\nlisten = \"127.0.0.1:0\"\n[stage]\nadress = \"127.0.0.1:502\"\n"
        << "[sample]\nwhite_reflectance = 1.5\n";
  }
  Result<DaemonRun> run = RunBrdfd({"--config", path}, dir.file("log").string());
  ASSERT_TRUE(run.ok()) << run.status().ToString();
  EXPECT_EQ(run->exit_code, 2) << run->err;
  EXPECT_NE(run->err.find("stage.adress"), std::string::npos) << run->err;
  EXPECT_NE(run->err.find("white_reflectance"), std::string::npos) << run->err;

  run = RunBrdfd({"--config", dir.file("missing.toml").string()}, dir.file("log").string());
  ASSERT_TRUE(run.ok());
  EXPECT_EQ(run->exit_code, 2) << run->err;
  EXPECT_NE(run->err.find("missing.toml"), std::string::npos) << run->err;
}

TEST(DaemonConfigTest, PlaintextOnANonLoopbackAddressIsServedWithAWarning) {
  DaemonRig rig;
  Result<int> dead = FreeTcpPort();
  ASSERT_TRUE(dead.ok());
  Status st = rig.StartDaemon(AbsentDevicesToml(rig.database(), *dead, "0.0.0.0:0"));
  ASSERT_TRUE(st.ok()) << st.ToString();
  EXPECT_NE(rig.log().find("PLAINTEXT"), std::string::npos) << rig.log();
  Result<int> code = rig.StopDaemon();
  ASSERT_TRUE(code.ok());
  EXPECT_EQ(*code, 0);
}

TEST(DaemonConfigTest, InterpolateLoopPinnedToACpuServesAndAnUnusableCpuIsRefused) {
  DaemonRig rig;
  Result<int> dead = FreeTcpPort();
  ASSERT_TRUE(dead.ok());
  cpu_set_t allowed;
  ASSERT_EQ(sched_getaffinity(0, sizeof(allowed), &allowed), 0);
  int usable = 0;
  while (!CPU_ISSET(usable, &allowed)) ++usable;
  Status st = rig.StartDaemon(AbsentDevicesToml(
      rig.database(), *dead, "127.0.0.1:0",
      "interpolate_threads = 2\ninterpolate_cpus = [" + std::to_string(usable) + "]\n"));
  ASSERT_TRUE(st.ok()) << st.ToString();
  EXPECT_NE(rig.log().find("Interpolate on 2 loop thread(s)"), std::string::npos) << rig.log();
  // An unknown session: the loop answered (NOT_FOUND from the slow lane's index load).
  v1::InterpolateRequest request;
  request.set_session_id("4242");
  request.mutable_direction()->mutable_iso()->set_theta_i(30);
  request.mutable_direction()->mutable_iso()->set_theta_o(30);
  request.mutable_direction()->mutable_iso()->set_phi(90);
  v1::InterpolateResponse response;
  EXPECT_EQ(rig.interpolation()
                .Interpolate(DaemonRig::Context(kAnalystToken).get(), request, &response)
                .error_code(),
            StatusCode::NOT_FOUND);
  EXPECT_EQ(rig.log().find("cannot pin"), std::string::npos) << rig.log();
  Result<int> code = rig.StopDaemon();
  ASSERT_TRUE(code.ok());
  EXPECT_EQ(*code, 0);

  // A CPU brdfd may not run on: start-up fails, naming the key and the CPUs it may use.
  TempDir dir("brdfd-cpus");
  const std::string path = dir.file("cpus.toml").string();
  {
    std::ofstream out(path);
    out << AbsentDevicesToml(dir.file("db.sqlite").string(), *dead, "127.0.0.1:0",
                             "interpolate_cpus = [1023]\n");
  }
  Result<DaemonRun> run = RunBrdfd({"--config", path}, dir.file("log").string());
  ASSERT_TRUE(run.ok()) << run.status().ToString();
  EXPECT_NE(run->exit_code, 0) << run->err;
  EXPECT_NE(run->err.find("server.interpolate_cpus: CPU 1023 is not one brdfd may run on"),
            std::string::npos)
      << run->err;
}

}  // namespace
}  // namespace brdf::testing
