// The Interpolation service in process, over gRPC on loopback, for tests: a real SQLite store
// filled through storage's API, the real IndexCache and InterpolationService behind a grpc::Server
// with Interpolate served by an InterpolateLoop, and the generated client stub. Sessions are made
// here as a rig would record them: a white reference, a dark, then sample readings at random
// directions (θi, θo in [0, 80], φ in [0, 180]) on the PR-650 grid.
//
// A test fixture derives from it, naming its temporary directory and its random seed; it may add
// server interceptors (ServerInterceptors), channel arguments (ChannelArgumentsFor) and choose how
// bright a sample reading is (SampleLevel).
#pragma once

#include <grpcpp/grpcpp.h>
#include <grpcpp/support/server_interceptor.h>
#include <gtest/gtest.h>

#include <chrono>
#include <cstdint>
#include <map>
#include <memory>
#include <random>
#include <string>
#include <utility>
#include <vector>

#include "brdf/v1/brdf.grpc.pb.h"
#include "daemon/api/common.h"
#include "daemon/api/interpolate_loop.h"
#include "daemon/api/interpolation.h"
#include "daemon/index/cache.h"
#include "daemon/rpc/auth.h"
#include "storage/session_store.h"
#include "tests/support/test_env.h"

namespace brdf::testing {

class InterpolationServiceTest : public ::testing::Test {
 protected:
  using InterceptorFactories =
      std::vector<std::unique_ptr<grpc::experimental::ServerInterceptorFactoryInterface>>;

  InterpolationServiceTest(const std::string& dir_name, std::uint64_t seed)
      : dir_(dir_name), rng_(seed) {}

  void SetUp() override {
    auto store = storage::SessionStore::Open(dir_.file("interpolation.db").string());
    ASSERT_TRUE(store.ok()) << store.status().ToString();
    store_ = std::move(*store);
    cache_ = std::make_unique<daemon::IndexCache>(store_);
    service_ = std::make_unique<daemon::InterpolationService>(*cache_, auth_, stopping_, streams_);

    grpc::ServerBuilder builder;
    int port = 0;
    builder.AddListeningPort("127.0.0.1:0", grpc::InsecureServerCredentials(), &port);
    builder.SetMaxReceiveMessageSize(daemon::kMaxReceiveMessageBytes);
    builder.RegisterService(service_.get());
    loop_ = std::make_unique<daemon::InterpolateLoop>(*service_, 1);
    loop_->AddQueues(builder);
    if (InterceptorFactories creators = ServerInterceptors(); !creators.empty()) {
      builder.experimental().SetInterceptorCreators(std::move(creators));
    }
    server_ = builder.BuildAndStart();
    ASSERT_TRUE(server_ != nullptr && port > 0);
    loop_->Start();
    grpc::ChannelArguments args;
    args.SetMaxReceiveMessageSize(-1);
    ChannelArgumentsFor(args);
    channel_ = grpc::CreateCustomChannel("127.0.0.1:" + std::to_string(port),
                                         grpc::InsecureChannelCredentials(), args);
    stub_ = v1::Interpolation::NewStub(channel_);
  }

  void TearDown() override {
    stopping_.Stop();
    loop_->BeginShutdown();
    if (server_) server_->Shutdown(std::chrono::system_clock::now() + std::chrono::seconds(2));
    loop_->Stop();
  }

  // Hooks: interceptors for the server, arguments for the client's channel, a sample's level.
  virtual InterceptorFactories ServerInterceptors() { return {}; }
  virtual void ChannelArgumentsFor(grpc::ChannelArguments&) {}
  virtual double SampleLevel(double /*theta_i*/) const { return 0.1; }

  // A running session: a white reference, a dark, then `samples` sample readings, with room for
  // `extra_steps` more. Returns its id.
  std::int64_t MakeSession(int samples, int extra_steps = 0) {
    storage::NewSession s;
    s.name = "interpolation test";
    s.plan_kind = "pose_list";
    s.plan_json = R"({"poseList": {"poses": [{"alpha": 0, "beta": 0, "delta": 0}]}})";
    s.created_by_role = "operator";
    s.white_reflectance = 0.99;
    std::vector<storage::StepRecord> steps;
    for (int i = 0; i < samples + 2 + extra_steps; ++i) {
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
    reference_ = Add(*id, storage::ReadingKind::kReference, {10, 0, 10, 180}, 1.0);
    dark_ = Add(*id, storage::ReadingKind::kDark, {}, 0.001);
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
  std::int64_t Add(std::int64_t session, storage::ReadingKind kind, const Directions& d,
                   double level) {
    return AddReading(session, kind, d, level).id;
  }
  // A sample reading at a random direction, as bright as SampleLevel says.
  storage::ReadingRecord AddSample(std::int64_t session) {
    std::uniform_real_distribution<double> theta(0, 80);
    std::uniform_real_distribution<double> phi(0, 180);
    const double ti = theta(rng_), to = theta(rng_), p = phi(rng_);
    return AddReading(session, storage::ReadingKind::kSample, {ti, 0, to, p}, SampleLevel(ti));
  }

  TempDir dir_;
  std::shared_ptr<storage::SessionStore> store_;
  std::unique_ptr<daemon::IndexCache> cache_;
  daemon::Authenticator auth_{{}};
  daemon::StopSignal stopping_;
  daemon::StreamRegistry streams_{daemon::ServerConfig{}, false};
  std::unique_ptr<daemon::InterpolationService> service_;
  std::unique_ptr<daemon::InterpolateLoop> loop_;  // serves service_'s Interpolate
  std::unique_ptr<grpc::Server> server_;
  std::shared_ptr<grpc::Channel> channel_;
  std::unique_ptr<v1::Interpolation::Stub> stub_;
  std::mt19937_64 rng_;
  std::map<std::int64_t, int> next_step_;
  std::int64_t reference_ = 0;
  std::int64_t dark_ = 0;
};

}  // namespace brdf::testing
