// The fixture of the interpolation tests over gRPC: brdf-sim (noiseless, --noise-scale 0) and
// brdfd as processes, an operator answering prompts once a test makes one, and calls of
// Interpolate and InterpolateBatch with an analyst's token. brdfd's log goes to standard error
// when a test fails (or with BRDF_TEST_SHOW_LOG set).
#pragma once

#include <gtest/gtest.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdlib>
#include <iostream>
#include <memory>
#include <string>
#include <vector>

#include "core/interp/interpolator.h"
#include "core/pose.h"
#include "tests/support/daemon/rig_teardown.h"
#include "tests/support/daemon/test_rig.h"

namespace brdf::testing {

class InterpolationRigTest : public ::testing::Test {
 protected:
  void SetUp() override {
    Status sim = rig_.StartSim({"--noise-scale", "0"});
    ASSERT_TRUE(sim.ok()) << sim.ToString();
    Status daemon = rig_.StartDaemon();
    ASSERT_TRUE(daemon.ok()) << daemon.ToString();
  }
  void TearDown() override {
    if (op_) {
      op_->Stop();
      for (const std::string& e : op_->errors()) ADD_FAILURE() << "operator: " << e;
    }
    StopDaemonExpectingCleanExit(rig_);
  }

  grpc::Status Interpolate(const std::string& id, const v1::DirectionQuery& direction,
                           v1::InterpolationMethod method, v1::Quantity quantity,
                           v1::InterpolationResult* result,
                           const v1::InterpolationOptions& options = {}) {
    v1::InterpolateRequest request;
    *request.mutable_options() = options;
    request.set_session_id(id);
    request.set_method(method);
    request.set_quantity(quantity);
    *request.mutable_direction() = direction;
    v1::InterpolateResponse response;
    grpc::Status st = rig_.interpolation().Interpolate(DaemonRig::Context(kAnalystToken).get(),
                                                       request, &response);
    *result = response.result();
    return st;
  }

  // The whole batch's results in order, or the call's error.
  grpc::Status Batch(const std::string& id, const std::vector<IsoDirection>& queries,
                     v1::InterpolationMethod method, v1::Quantity quantity,
                     std::vector<v1::InterpolationResult>* results,
                     const v1::InterpolationOptions& options = {}) {
    v1::InterpolateBatchRequest batch;
    batch.set_session_id(id);
    batch.set_method(method);
    batch.set_quantity(quantity);
    *batch.mutable_options() = options;
    for (const IsoDirection& q : queries) *batch.add_directions() = Iso(q);
    auto context = DaemonRig::Context(kAnalystToken);
    auto reader = rig_.interpolation().InterpolateBatch(context.get(), batch);
    v1::InterpolateBatchChunk chunk;
    results->clear();
    while (reader->Read(&chunk)) {
      for (const v1::InterpolationResult& r : chunk.results()) results->push_back(r);
    }
    return reader->Finish();
  }

  // Submits `plan`, answers its prompts and waits until it completes; *id is the session's.
  // Use as ASSERT_NO_FATAL_FAILURE(Record(plan, &id)).
  void Record(const std::string& plan, std::string* id) {
    Result<v1::Session> submitted = rig_.Submit(plan);
    ASSERT_TRUE(submitted.ok()) << submitted.status().ToString();
    *id = submitted->session_id();
    op_ = std::make_unique<GrpcOperator>(rig_, *id);
    const v1::Session done =
        rig_.WaitForState(*id, v1::SESSION_STATE_COMPLETED, std::chrono::seconds(60));
    ASSERT_EQ(done.state(), v1::SESSION_STATE_COMPLETED) << done.DebugString();
  }

  // Queries half-way between consecutive readings of `set` (inside the data), and three near the
  // mirror direction, where options matter most.
  static std::vector<IsoDirection> MidpointQueries(const interp::SampleSet& set) {
    std::vector<IsoDirection> queries;
    for (std::size_t i = 1; i < set.size(); ++i) {
      const auto a = set.coords(i - 1), b = set.coords(i);
      queries.push_back({(a[0] + b[0]) / 2, (a[1] + b[1]) / 2, (a[2] + b[2]) / 2});
    }
    for (double t : {15.0, 18.0, 22.0}) queries.push_back({t, t + 1, 176});
    return queries;
  }

  // max_b |a_b − b_b| / max_b |b_b|.
  static double RelativeGap(const google::protobuf::RepeatedField<double>& a,
                            const std::vector<double>& b) {
    double diff = 0, scale = 0;
    for (std::size_t i = 0; i < b.size(); ++i) {
      diff = std::max(diff, std::abs(a[static_cast<int>(i)] - b[i]));
      scale = std::max(scale, std::abs(b[i]));
    }
    return diff / scale;
  }

  static v1::DirectionQuery Four(double theta_i, double phi_i, double theta_o, double phi_o) {
    v1::DirectionQuery q;
    q.mutable_four()->set_theta_i(theta_i);
    q.mutable_four()->set_phi_i(phi_i);
    q.mutable_four()->set_theta_o(theta_o);
    q.mutable_four()->set_phi_o(phi_o);
    return q;
  }

  static v1::DirectionQuery Iso(const IsoDirection& d) {
    v1::DirectionQuery q;
    q.mutable_iso()->set_theta_i(d.theta_i);
    q.mutable_iso()->set_theta_o(d.theta_o);
    q.mutable_iso()->set_phi(d.phi);
    return q;
  }

  DaemonRig rig_;
  std::unique_ptr<GrpcOperator> op_;
};

}  // namespace brdf::testing
