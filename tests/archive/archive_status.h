// What a rig's brdfd says of its archive (GetRigStatus's ArchiveStatus), for the archive tests.
#pragma once

#include <gtest/gtest.h>

#include <chrono>
#include <functional>
#include <thread>

#include "tests/support/daemon/test_rig.h"

namespace brdf::testing {

// The rig's archive status now; a failed GetRigStatus fails the test (and gives an empty status).
inline v1::ArchiveStatus RigArchiveStatus(DaemonRig& rig) {
  v1::RigStatus status;
  grpc::Status st = rig.control().GetRigStatus(DaemonRig::Context().get(), {}, &status);
  EXPECT_TRUE(st.ok()) << st.error_message();
  return status.archive();
}

// Asks every 50 ms until `done` holds for the rig's archive status; false after `timeout`.
inline bool WaitRigArchiveStatus(DaemonRig& rig,
                                 const std::function<bool(const v1::ArchiveStatus&)>& done,
                                 std::chrono::seconds timeout = std::chrono::seconds(30)) {
  const auto deadline = std::chrono::steady_clock::now() + timeout;
  while (std::chrono::steady_clock::now() < deadline) {
    if (done(RigArchiveStatus(rig))) return true;
    std::this_thread::sleep_for(std::chrono::milliseconds(50));
  }
  return false;
}

}  // namespace brdf::testing
