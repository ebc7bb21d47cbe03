// The heavy streams' work permits (daemon/rpc/work_permits.h): a free permit goes to the waiting
// token that holds the fewest, the earliest arrived among equals; a waiter whose call is
// cancelled leaves the queue; a release hands its permit on at once.
#include "daemon/rpc/work_permits.h"

#include <gtest/gtest.h>

#include <atomic>
#include <chrono>
#include <thread>

namespace brdf::daemon {
namespace {

using namespace std::chrono_literals;

bool Never() {
  return false;
}

// Waits up to 5 s for `done`.
template <class Done>
bool Eventually(Done done) {
  for (int i = 0; i < 500 && !done(); ++i) std::this_thread::sleep_for(10ms);
  return done();
}

TEST(WorkPermits, AFreePermitGoesToTheWaitingTokenHoldingTheFewest) {
  WorkPermits permits(2);
  ASSERT_TRUE(permits.Acquire("a", Never));
  ASSERT_TRUE(permits.Acquire("a", Never));
  std::atomic<bool> a_third{false}, b_first{false};
  std::thread a([&] { a_third = permits.Acquire("a", Never); });
  ASSERT_TRUE(Eventually([&] { return permits.waiting() == 1; }));
  std::thread b([&] { b_first = permits.Acquire("b", Never); });
  ASSERT_TRUE(Eventually([&] { return permits.waiting() == 2; }));

  // "a" then holds 1, "b" none: b's stream goes first although a's came earlier.
  permits.Release("a");
  ASSERT_TRUE(Eventually([&] { return b_first.load(); }));
  std::this_thread::sleep_for(50ms);
  EXPECT_FALSE(a_third.load());
  EXPECT_EQ(permits.working(), 2);

  permits.Release("a");
  ASSERT_TRUE(Eventually([&] { return a_third.load(); }));
  EXPECT_EQ(permits.waiting(), 0);
  a.join();
  b.join();
  permits.Release("a");
  permits.Release("b");
  EXPECT_EQ(permits.working(), 0);
}

TEST(WorkPermits, AmongEqualHoldersTheEarliestWaiterGoesFirst) {
  WorkPermits permits(1);
  ASSERT_TRUE(permits.Acquire("x", Never));
  std::atomic<int> order{0}, first{0}, second{0};
  std::thread one([&] {
    if (permits.Acquire("a", Never)) first = ++order;
  });
  ASSERT_TRUE(Eventually([&] { return permits.waiting() == 1; }));
  std::thread two([&] {
    if (permits.Acquire("b", Never)) second = ++order;
  });
  ASSERT_TRUE(Eventually([&] { return permits.waiting() == 2; }));
  permits.Release("x");
  ASSERT_TRUE(Eventually([&] { return first.load() == 1; }));
  EXPECT_EQ(second.load(), 0);
  permits.Release("a");
  ASSERT_TRUE(Eventually([&] { return second.load() == 2; }));
  one.join();
  two.join();
  permits.Release("b");
}

TEST(WorkPermits, ACancelledWaiterLeavesTheQueueWithoutAPermit) {
  WorkPermits permits(1);
  ASSERT_TRUE(permits.Acquire("a", Never));
  std::atomic<bool> cancelled{false}, got{true}, returned{false};
  std::thread waiter([&] {
    got = permits.Acquire("b", [&] { return cancelled.load(); });
    returned = true;
  });
  ASSERT_TRUE(Eventually([&] { return permits.waiting() == 1; }));
  cancelled = true;
  ASSERT_TRUE(Eventually([&] { return returned.load(); }));  // within the half-second look
  waiter.join();
  EXPECT_FALSE(got.load());
  EXPECT_EQ(permits.waiting(), 0);
  EXPECT_EQ(permits.working(), 1);
  // Its place is not kept: the next release leaves the permit free for whoever asks.
  permits.Release("a");
  EXPECT_EQ(permits.working(), 0);
  EXPECT_TRUE(permits.Acquire("c", Never));
}

TEST(WorkPermits, ACallCancelledBeforeItsTurnGetsNoPermit) {
  WorkPermits permits(1);
  ASSERT_TRUE(permits.Acquire("a", Never));
  EXPECT_FALSE(permits.Acquire("b", [] { return true; }));
  EXPECT_EQ(permits.waiting(), 0);
}

}  // namespace
}  // namespace brdf::daemon
