// Authentication and roles on EVERY RPC: the methods are enumerated from brdf.proto's descriptor
// (not from a list kept by hand), so an RPC added later is checked too, and the test refuses to
// pass until the new RPC is classified as a control or a read call below. Requests are sent as
// raw bytes through a generic stub, so one loop covers unary and streaming calls alike.
// Also: tokens never reach the log (at trace level), refusals of a role are logged by name, the
// audit log names the caller and role of every control action, the default bind is loopback.
#include <gtest/gtest.h>

#include <chrono>
#include <fstream>
#include <iterator>
#include <map>
#include <set>
#include <sstream>

#include "daemon/api/server.h"
#include "daemon/config/config.h"
#include "tests/support/daemon/raw_call.h"
#include "tests/support/daemon/test_rig.h"
#include "tests/support/daemon/test_util.h"
#include "tests/support/plan_fixtures.h"

namespace brdf::testing {
namespace {

using namespace std::chrono_literals;
using google::protobuf::MethodDescriptor;
using grpc::StatusCode;

enum class Needs { kRead, kControl };

// What each RPC needs (brdf.proto's header). Every method of the descriptor must be here.
const std::map<std::string, Needs>& Classification() {
  static const std::map<std::string, Needs> table = {
      {"brdf.v1.Control.SubmitPlan", Needs::kControl},
      {"brdf.v1.Control.ValidatePlan", Needs::kRead},
      {"brdf.v1.Control.StartSession", Needs::kControl},
      {"brdf.v1.Control.PauseSession", Needs::kControl},
      {"brdf.v1.Control.ResumeSession", Needs::kControl},
      {"brdf.v1.Control.AbortSession", Needs::kControl},
      {"brdf.v1.Control.AnswerPrompt", Needs::kControl},
      {"brdf.v1.Control.GetSession", Needs::kRead},
      {"brdf.v1.Control.ListSessions", Needs::kRead},
      {"brdf.v1.Control.ListSessionEvents", Needs::kRead},
      {"brdf.v1.Control.ListAdaptiveRounds", Needs::kRead},
      {"brdf.v1.Control.GetRigStatus", Needs::kRead},
      {"brdf.v1.Control.WatchSession", Needs::kRead},
      {"brdf.v1.Control.WhoAmI", Needs::kRead},
      {"brdf.v1.Data.StreamReadings", Needs::kRead},
      {"brdf.v1.Data.Export", Needs::kRead},
      {"brdf.v1.Data.StreamReadingPoints", Needs::kRead},
      {"brdf.v1.Interpolation.Interpolate", Needs::kRead},
      {"brdf.v1.Interpolation.InterpolateBatch", Needs::kRead},
      {"brdf.v1.Interpolation.RenderAppearance", Needs::kRead},
  };
  return table;
}

const std::string kSmallPlan = plans::OnePose();

// A token of the right shape that no daemon here knows.
constexpr const char* kStrangerToken = "zz-stranger-7d41c09e5ab2f386";

class AuthMatrixTest : public ::testing::Test {
 protected:
  void SetUp() override {
    Result<int> port = FreeTcpPort();
    ASSERT_TRUE(port.ok());
    // Trace: the most the daemon ever logs; tokens must not be in it.
    Status st = rig_.StartDaemon(AbsentDevicesToml(rig_.database(), *port, "trace"));
    ASSERT_TRUE(st.ok()) << st.ToString();
    Result<v1::Session> queued = rig_.Submit(kSmallPlan, /*start_now=*/false);
    ASSERT_TRUE(queued.ok()) << queued.status().ToString();
    session_id_ = queued->session_id();
  }
  void TearDown() override {
    // Whatever the test did, no token (not even a wrong one) is in the log.
    std::ifstream in(rig_.log_path());
    const std::string log((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
    EXPECT_NE(log.find("bearer token(s) configured"), std::string::npos) << "no log to check";
    for (const char* token : {kOperatorToken, kAnalystToken, kStrangerToken}) {
      EXPECT_EQ(log.find(token), std::string::npos) << "the log holds the token " << token;
    }
    if (rig_.daemon() != nullptr) {
      Result<int> code = rig_.StopDaemon();
      EXPECT_TRUE(code.ok() && *code == 0)
          << (code.ok() ? "exit code " + std::to_string(*code) : code.status().ToString());
    }
    if (HasFailure()) std::cerr << "---- brdfd log ----\n" << rig_.log() << "\n----\n";
  }

  DaemonRig rig_;
  std::string session_id_;
};

TEST(AuthMatrixClassificationTest, EveryRpcOfTheProtoIsClassified) {
  const std::vector<const MethodDescriptor*> methods = AllMethods();
  std::set<std::string> seen;
  for (const MethodDescriptor* m : methods) {
    seen.insert(m->full_name());
    EXPECT_EQ(Classification().count(m->full_name()), 1u)
        << m->full_name()
        << " is a new RPC: classify it in tests/daemon/security/auth_matrix_test.cc (control or "
           "read) and, if it changes anything, in rpc/auth.cc's MethodAccess";
  }
  for (const auto& [name, needs] : Classification()) {
    EXPECT_EQ(seen.count(name), 1u) << name << " is no longer in brdf.proto";
  }
  // The three services are all there (the loop above would pass on an empty file).
  std::set<std::string> services;
  for (const MethodDescriptor* m : methods) services.insert(m->service()->full_name());
  EXPECT_EQ(services,
            (std::set<std::string>{"brdf.v1.Control", "brdf.v1.Data", "brdf.v1.Interpolation"}));
}

TEST_F(AuthMatrixTest, EveryRpcRefusesMissingWrongAndMalformedTokens) {
  const std::string op(kOperatorToken);
  const std::vector<std::pair<std::string, std::string>> headers = {
      {"no authorization metadata", ""},
      {"a token of no configured caller", std::string("Bearer ") + kStrangerToken},
      {"a prefix of the operator token", "Bearer " + op.substr(0, op.size() - 1)},
      {"the operator token and one byte more", "Bearer " + op + "x"},
      {"another scheme", "Basic " + op},
      {"the scheme without a token", "Bearer "},
      {"an oversize header", "Bearer " + std::string(5000, 'a')},
  };
  for (const MethodDescriptor* method : AllMethods()) {
    for (const auto& [what, header] : headers) {
      RawReply reply =
          CallRaw(rig_.channel(), PathOf(*method), RequestBytes(*method, session_id_), header);
      EXPECT_EQ(reply.status.error_code(), StatusCode::UNAUTHENTICATED)
          << method->full_name() << " with " << what << ": " << reply.status.error_message();
      EXPECT_NE(reply.status.error_message().find(method->name()), std::string::npos)
          << method->full_name() << ": " << reply.status.error_message();
      EXPECT_EQ(reply.messages, 0) << method->full_name() << " answered " << what;
    }
  }
  // Nothing was done: the session is still queued.
  Result<v1::Session> session = rig_.Get(session_id_);
  ASSERT_TRUE(session.ok());
  EXPECT_EQ(session->state(), v1::SESSION_STATE_QUEUED);
}

TEST_F(AuthMatrixTest, AnalystsMayReadEverythingAndControlNothingOperatorsMayDoAll) {
  const std::string analyst = std::string("Bearer ") + kAnalystToken;
  const std::string op = std::string("bearer ") + kOperatorToken;  // the scheme is case-blind
  for (const MethodDescriptor* method : AllMethods()) {
    auto it = Classification().find(method->full_name());
    ASSERT_NE(it, Classification().end()) << method->full_name();
    // The analyst aims at the real queued session: a refused verb must not touch it.
    RawReply reply = CallRaw(rig_.channel(), PathOf(*method), RequestBytes(*method, session_id_),
                             analyst, 15s, /*max_messages=*/1);
    if (it->second == Needs::kControl) {
      EXPECT_EQ(reply.status.error_code(), StatusCode::PERMISSION_DENIED)
          << method->full_name() << ": " << reply.status.error_message();
      EXPECT_NE(reply.status.error_message().find("operator"), std::string::npos)
          << reply.status.error_message();
      // The refusal is logged with the token's name (never the token).
      EXPECT_NE(rig_.log().find(method->name() + ": refused token \"test-analyst\""),
                std::string::npos)
          << method->full_name();
    } else {
      EXPECT_NE(reply.status.error_code(), StatusCode::UNAUTHENTICATED) << method->full_name();
      EXPECT_NE(reply.status.error_code(), StatusCode::PERMISSION_DENIED)
          << method->full_name() << ": " << reply.status.error_message();
    }
    // The operator passes authorization everywhere (empty requests: refused as arguments, so
    // nothing changes).
    reply = CallRaw(rig_.channel(), PathOf(*method), RequestBytes(*method), op, 15s, 1);
    EXPECT_NE(reply.status.error_code(), StatusCode::UNAUTHENTICATED) << method->full_name();
    EXPECT_NE(reply.status.error_code(), StatusCode::PERMISSION_DENIED)
        << method->full_name() << ": " << reply.status.error_message();
  }
  Result<v1::Session> session = rig_.Get(session_id_);
  ASSERT_TRUE(session.ok());
  EXPECT_EQ(session->state(), v1::SESSION_STATE_QUEUED);
}

TEST_F(AuthMatrixTest, WhoAmITellsEachTokenItsNameAndRoleAndCannotBeTalkedInto) {
  auto who = [&](const char* token, const std::vector<std::pair<std::string, std::string>>& extra) {
    std::unique_ptr<grpc::ClientContext> context = DaemonRig::Context(token);
    for (const auto& [key, value] : extra) context->AddMetadata(key, value);
    v1::Caller caller;
    grpc::Status st = rig_.control().WhoAmI(context.get(), v1::WhoAmIRequest(), &caller);
    EXPECT_TRUE(st.ok()) << st.error_message();
    return caller;
  };
  v1::Caller op = who(kOperatorToken, {});
  EXPECT_EQ(op.name(), "test-operator");
  EXPECT_EQ(op.role(), "operator");
  EXPECT_EQ(op.server(), "brdfd");
  v1::Caller analyst = who(kAnalystToken, {});
  EXPECT_EQ(analyst.name(), "test-analyst");
  EXPECT_EQ(analyst.role(), "analyst");
  // The caller is its token's, not anything the client says about itself, and not the caller of
  // an earlier call on the same connection.
  v1::Caller pretending =
      who(kAnalystToken, {{"brdf.caller.role", "operator"}, {"brdf.caller.name", "test-operator"}});
  EXPECT_EQ(pretending.name(), "test-analyst");
  EXPECT_EQ(pretending.role(), "analyst");
  // Without a token: refused at the gate like every read.
  grpc::ClientContext none;
  v1::Caller nobody;
  EXPECT_EQ(rig_.control().WhoAmI(&none, v1::WhoAmIRequest(), &nobody).error_code(),
            StatusCode::UNAUTHENTICATED);
}

TEST_F(AuthMatrixTest, AuditLogNamesTheCallerAndRoleOfEveryControlAction) {
  auto ctx = [] { return DaemonRig::Context(kOperatorToken); };
  // Every control verb once (some are refused by the session's state; those are audited too).
  v1::StartSessionRequest start;
  start.set_session_id(session_id_);
  v1::StartSessionResponse started;
  rig_.control().StartSession(ctx().get(), start, &started);
  v1::PauseSessionRequest pause;
  pause.set_session_id(session_id_);
  pause.set_mode(v1::PAUSE_MODE_IMMEDIATE);
  v1::PauseSessionResponse paused;
  rig_.control().PauseSession(ctx().get(), pause, &paused);
  v1::ResumeSessionRequest resume;
  resume.set_session_id(session_id_);
  v1::ResumeSessionResponse resumed;
  rig_.control().ResumeSession(ctx().get(), resume, &resumed);
  v1::AnswerPromptRequest answer;
  answer.set_session_id(session_id_);
  answer.set_step_index(0);
  v1::AnswerPromptResponse answered;
  rig_.control().AnswerPrompt(ctx().get(), answer, &answered);
  v1::AbortSessionRequest abort;
  abort.set_session_id(session_id_);
  abort.set_reason("audit test");
  v1::AbortSessionResponse aborted;
  grpc::Status st = rig_.control().AbortSession(ctx().get(), abort, &aborted);
  EXPECT_TRUE(st.ok()) << st.error_message();
  // An analyst's attempt is refused before it is an action.
  rig_.control().AbortSession(DaemonRig::Context(kAnalystToken).get(), abort, &aborted);

  Result<std::vector<AuditRow>> rows = AuditRows(rig_.database());
  ASSERT_TRUE(rows.ok()) << rows.status().ToString();
  std::set<std::string> actions;
  for (const AuditRow& row : *rows) {
    if (row.role == "daemon") continue;  // the daemon's own (recovery at start-up)
    EXPECT_EQ(row.role, "operator") << row.action << " " << row.detail;
    EXPECT_EQ(row.actor, kOperatorName) << row.action;
    for (const char* token : {kOperatorToken, kAnalystToken}) {
      EXPECT_EQ(row.actor.find(token), std::string::npos);
      EXPECT_EQ(row.detail.find(token), std::string::npos);
    }
    actions.insert(row.action);
  }
  for (const char* action : {"session.submit", "session.start", "session.pause", "session.resume",
                             "session.answer_prompt", "session.abort"}) {
    EXPECT_EQ(actions.count(action), 1u) << action << " is not in the audit log";
  }
}

TEST(DefaultBindTest, TheDefaultAddressIsLoopbackAndOnlyLiteralLoopbacksCount) {
  Result<daemon::Config> config = daemon::ParseConfig("");
  ASSERT_TRUE(config.ok()) << config.status().ToString();
  EXPECT_EQ(config->server.listen, "127.0.0.1:50051");
  EXPECT_FALSE(config->server.tls.has_value());
  EXPECT_TRUE(daemon::IsLoopbackAddress(config->server.listen));
  for (const char* local : {"127.0.0.1:1", "127.8.9.10:1", "localhost:1", "[::1]:1",
                            "[::ffff:127.0.0.1]:1", "unix:/run/brdfd.sock"}) {
    EXPECT_TRUE(daemon::IsLoopbackAddress(local)) << local;
  }
  for (const char* remote : {"0.0.0.0:1", "[::]:1", "10.0.0.7:1", "192.168.1.2:50051",
                             "127.example.org:1", "lab-pc:1", "[::ffff:10.0.0.1]:1"}) {
    EXPECT_FALSE(daemon::IsLoopbackAddress(remote)) << remote;
  }
}

}  // namespace
}  // namespace brdf::testing
