#include "core/status.h"

#include <gtest/gtest.h>

#include <chrono>
#include <thread>

#include "core/call_context.h"

namespace brdf {
namespace {

TEST(StatusTest, DeviceErrorCarriesCodeAndContext) {
  Status s = DeviceError(19, "light level too high").WithContext("PR-650 M0");
  EXPECT_FALSE(s.ok());
  EXPECT_EQ(s.code(), StatusCode::kDeviceError);
  EXPECT_EQ(s.device_code(), 19);
  EXPECT_EQ(s.ToString(), "device_error 19: PR-650 M0: light level too high");
}

TEST(StatusTest, ResultHoldsValueOrStatus) {
  Result<int> good = 4;
  Result<int> bad = Timeout("no reply");
  ASSERT_TRUE(good.ok());
  EXPECT_EQ(*good, 4);
  EXPECT_FALSE(bad.ok());
  EXPECT_EQ(bad.status().code(), StatusCode::kTimeout);
}

TEST(CallContextTest, CancelWakesWaiter) {
  CancelToken token;
  std::thread t([token]() mutable {
    std::this_thread::sleep_for(std::chrono::milliseconds(20));
    token.Cancel("pause immediate");
  });
  auto ctx = CallContext::WithTimeout(std::chrono::seconds(30), token);
  bool slept = ctx.clock().SleepFor(std::chrono::seconds(30), &ctx.cancel());
  t.join();
  EXPECT_FALSE(slept);
  EXPECT_TRUE(ctx.cancelled());
  EXPECT_EQ(ctx.cancel().reason(), "pause immediate");
}

TEST(CallContextTest, NarrowTakesEarlierDeadline) {
  auto ctx = CallContext::WithTimeout(std::chrono::milliseconds(10));
  auto narrow = ctx.Narrow(std::chrono::hours(1));
  EXPECT_EQ(narrow.deadline(), ctx.deadline());
  std::this_thread::sleep_for(std::chrono::milliseconds(15));
  EXPECT_TRUE(narrow.expired());
  EXPECT_EQ(narrow.remaining(), std::chrono::steady_clock::duration::zero());
}

}  // namespace
}  // namespace brdf
