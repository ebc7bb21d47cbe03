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

// Halves an even number; an odd one is refused.
Result<int> Half(int n) {
  if (n % 2 != 0) return InvalidArgument(std::to_string(n) + " is odd");
  return n / 2;
}

// Halves twice through BRDF_ASSIGN_OR_RETURN, once into a new name and once into an existing one.
Result<int> Quarter(int n) {
  BRDF_ASSIGN_OR_RETURN(const int half, Half(n));
  int quarter = -1;
  BRDF_ASSIGN_OR_RETURN(quarter, Half(half));
  return quarter;
}

TEST(StatusTest, AssignOrReturnUnwrapsOrReturnsTheStatus) {
  ASSERT_TRUE(Quarter(12).ok());
  EXPECT_EQ(*Quarter(12), 3);
  EXPECT_EQ(Quarter(7).status().message(), "7 is odd");  // the first call fails
  EXPECT_EQ(Quarter(6).status().message(), "3 is odd");  // the second one does
  EXPECT_EQ(Quarter(6).status().code(), StatusCode::kInvalidArgument);
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
