// A test fixture holding a fresh PostgreSQL server (pg/server.h) in pg_, started for each test;
// the test is skipped, saying why, when PostgreSQL is not installed. Header-only: the test
// executables link GoogleTest, brdf_test_support does not.
#pragma once

#include <gtest/gtest.h>

#include <memory>
#include <string>
#include <utility>

#include "tests/support/pg/server.h"

namespace brdf::testing {

class PgServerTest : public ::testing::Test {
 protected:
  // A fixture's own SetUp calls this first, then returns unless PgReady().
  void SetUp() override {
    if (std::string why = PgServer::Unavailable(); !why.empty()) GTEST_SKIP() << why;
    Result<std::unique_ptr<PgServer>> pg = PgServer::Start();
    ASSERT_TRUE(pg.ok()) << pg.status().ToString();
    pg_ = std::move(*pg);
  }
  // False when SetUp skipped the test or could not start the server.
  bool PgReady() const { return !IsSkipped() && !HasFatalFailure(); }

  std::unique_ptr<PgServer> pg_;
};

}  // namespace brdf::testing
