// The health service (grpc.health.v1.Health) in process, over gRPC on loopback, with the
// generated stubs of proto/grpc/health/v1/health.proto: Check of known and unknown services, and
// Watch streaming the status now and then each change, through to the server's shutdown.
#include <grpcpp/grpcpp.h>
#include <gtest/gtest.h>

#include <chrono>
#include <memory>
#include <thread>

#include "daemon/api/health.h"

namespace brdf::daemon {
namespace {

using namespace std::chrono_literals;
using grpc::health::v1::HealthCheckRequest;
using grpc::health::v1::HealthCheckResponse;

class HealthServiceTest : public ::testing::Test {
 protected:
  void SetUp() override {
    grpc::ServerBuilder builder;
    int port = 0;
    builder.AddListeningPort("127.0.0.1:0", grpc::InsecureServerCredentials(), &port);
    builder.RegisterService(&health_);
    health_.ServeOn(loop_);  // Check, as server.cc serves it
    loop_.AddQueue(builder);
    server_ = builder.BuildAndStart();
    loop_.Start();
    ASSERT_TRUE(server_ != nullptr && port > 0);
    stub_ = grpc::health::v1::Health::NewStub(grpc::CreateChannel(
        "127.0.0.1:" + std::to_string(port), grpc::InsecureChannelCredentials()));
  }
  void TearDown() override {
    stopping_.Stop();
    loop_.BeginShutdown();
    server_->Shutdown(std::chrono::system_clock::now() + 2s);
    loop_.Stop();
  }

  grpc::Status Check(const std::string& service, HealthCheckResponse* response) {
    grpc::ClientContext context;
    context.set_deadline(std::chrono::system_clock::now() + 5s);
    HealthCheckRequest request;
    request.set_service(service);
    return stub_->Check(&context, request, response);
  }

  StopSignal stopping_;
  StreamRegistry streams_{ServerConfig{}, false};
  ControlLoop loop_{1};
  HealthService health_{stopping_, streams_};
  std::unique_ptr<grpc::Server> server_;
  std::unique_ptr<grpc::health::v1::Health::Stub> stub_;
};

TEST_F(HealthServiceTest, CheckAnswersKnownServicesAndRefusesOthers) {
  HealthCheckResponse response;
  EXPECT_EQ(Check("", &response).error_code(), grpc::StatusCode::NOT_FOUND);  // nothing set yet
  health_.SetServingStatus("", true);
  health_.SetServingStatus("brdf.v1.Control", true);
  ASSERT_TRUE(Check("", &response).ok());
  EXPECT_EQ(response.status(), HealthCheckResponse::SERVING);
  ASSERT_TRUE(Check("brdf.v1.Control", &response).ok());
  EXPECT_EQ(response.status(), HealthCheckResponse::SERVING);
  const grpc::Status unknown = Check("no.such.Service", &response);
  EXPECT_EQ(unknown.error_code(), grpc::StatusCode::NOT_FOUND);
  EXPECT_NE(unknown.error_message().find("no.such.Service"), std::string::npos);
  EXPECT_NE(unknown.error_message().find("ask for one of: \"\" (the server), brdf.v1.Control"),
            std::string::npos)
      << unknown.error_message();
  // Shutting down: every known service at once.
  health_.SetServingStatus(false);
  ASSERT_TRUE(Check("brdf.v1.Control", &response).ok());
  EXPECT_EQ(response.status(), HealthCheckResponse::NOT_SERVING);
  ASSERT_TRUE(Check("", &response).ok());
  EXPECT_EQ(response.status(), HealthCheckResponse::NOT_SERVING);
}

TEST_F(HealthServiceTest, WatchStreamsEachChangeAndEndsWhenTheServerStops) {
  grpc::ClientContext context;
  context.set_deadline(std::chrono::system_clock::now() + 10s);
  HealthCheckRequest request;
  request.set_service("brdf.v1.Data");
  auto reader = stub_->Watch(&context, request);
  HealthCheckResponse response;
  ASSERT_TRUE(reader->Read(&response));
  EXPECT_EQ(response.status(), HealthCheckResponse::SERVICE_UNKNOWN);  // not known yet

  health_.SetServingStatus("other.Service", true);  // a change elsewhere: nothing sent
  health_.SetServingStatus("brdf.v1.Data", true);
  ASSERT_TRUE(reader->Read(&response));
  EXPECT_EQ(response.status(), HealthCheckResponse::SERVING);
  health_.SetServingStatus("brdf.v1.Data", true);  // the same status again: nothing sent

  // The daemon's shutdown: NOT_SERVING, then the stop ends the stream.
  health_.SetServingStatus(false);
  stopping_.Stop();
  ASSERT_TRUE(reader->Read(&response));
  EXPECT_EQ(response.status(), HealthCheckResponse::NOT_SERVING);
  EXPECT_FALSE(reader->Read(&response));
  const grpc::Status st = reader->Finish();
  EXPECT_EQ(st.error_code(), grpc::StatusCode::UNAVAILABLE) << st.error_message();
}

TEST_F(HealthServiceTest, AWatcherThatCancelsIsLetGo) {
  health_.SetServingStatus("", true);
  auto context = std::make_unique<grpc::ClientContext>();
  HealthCheckRequest request;
  auto reader = stub_->Watch(context.get(), request);
  HealthCheckResponse response;
  ASSERT_TRUE(reader->Read(&response));
  EXPECT_EQ(response.status(), HealthCheckResponse::SERVING);
  context->TryCancel();
  EXPECT_EQ(reader->Finish().error_code(), grpc::StatusCode::CANCELLED);
  // The server's shutdown does not wait for the watcher (its handler has returned): quick.
  const auto before = std::chrono::steady_clock::now();
  server_->Shutdown(std::chrono::system_clock::now() + 5s);
  EXPECT_LT(std::chrono::steady_clock::now() - before, 3s);
}

}  // namespace
}  // namespace brdf::daemon
