// The end of a test with brdfd as a process: a clean stop is part of every such test (SIGTERM →
// exit 0), and brdfd's log goes to standard error when the test failed (or with
// BRDF_TEST_SHOW_LOG set). Call it from a fixture's TearDown, after the test's own clients
// stopped.
#pragma once

#include <gtest/gtest.h>

#include <cstdlib>
#include <iostream>
#include <string>

#include "tests/support/daemon/test_rig.h"

namespace brdf::testing {

inline void StopDaemonExpectingCleanExit(DaemonRig& rig) {
  if (rig.daemon() != nullptr) {
    Result<int> code = rig.StopDaemon();
    EXPECT_TRUE(code.ok() && *code == 0)
        << (code.ok() ? "exit code " + std::to_string(*code) : code.status().ToString());
  }
  if (::testing::Test::HasFailure() || std::getenv("BRDF_TEST_SHOW_LOG") != nullptr) {
    std::cerr << "---- brdfd log ----\n" << rig.log() << "\n----\n";
  }
}

}  // namespace brdf::testing
