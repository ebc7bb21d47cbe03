// The fixture of the session tests over gRPC: brdf-sim and brdfd as processes, and the gRPC
// operators a test starts (Watch), stopped at its end with their errors as failures. A clean stop
// of brdfd is part of every test (SIGTERM → exit 0). brdfd's log goes to standard error when a
// test fails (or with BRDF_TEST_SHOW_LOG set).
#pragma once

#include <gtest/gtest.h>

#include <cstdint>
#include <memory>
#include <string>
#include <vector>

#include "tests/support/daemon/rig_teardown.h"
#include "tests/support/daemon/test_rig.h"
#include "tests/support/daemon/test_util.h"

namespace brdf::testing {

class SessionRigTest : public ::testing::Test {
 protected:
  void SetUp() override {
    Status sim = rig_.StartSim();
    ASSERT_TRUE(sim.ok()) << sim.ToString();
    Status daemon = rig_.StartDaemon();
    ASSERT_TRUE(daemon.ok()) << daemon.ToString();
  }

  void TearDown() override {
    for (auto& op : operators_) {
      op->Stop();
      for (const std::string& e : op->errors()) ADD_FAILURE() << "operator: " << e;
    }
    operators_.clear();
    StopDaemonExpectingCleanExit(rig_);
  }

  // A gRPC operator watching the session (and answering its prompts unless `answering` is false)
  // until the test ends.
  GrpcOperator& Watch(const std::string& session_id, bool answering = true) {
    operators_.push_back(std::make_unique<GrpcOperator>(rig_, session_id, answering));
    return *operators_.back();
  }

  // The database holds every planned step once, one reading per done measuring step, nothing
  // else; and storage's own check agrees.
  void ExpectIntact(std::int64_t id) {
    Result<DbSessionCounts> c = CountSession(rig_.database(), id);
    ASSERT_TRUE(c.ok()) << c.status().ToString();
    EXPECT_EQ(c->steps, c->total_steps);
    EXPECT_EQ(c->step_index_gaps, 0);
    EXPECT_EQ(c->duplicate_readings, 0);
    EXPECT_EQ(c->orphan_readings, 0);
    EXPECT_EQ(c->readings, c->measuring_steps_done);
    EXPECT_EQ(c->done_steps_recorded, c->steps_done);
    Result<std::string> problems = StorageProblems(rig_.database(), id);
    ASSERT_TRUE(problems.ok()) << problems.status().ToString();
    EXPECT_EQ(*problems, "");
  }

  DaemonRig rig_;
  std::vector<std::unique_ptr<GrpcOperator>> operators_;
};

}  // namespace brdf::testing
