// The event bus on its own: bounded queues that drop the oldest event, late subscribers that get
// the snapshot and the open prompt first, and subscriptions that end with the session.
#include "daemon/engine/event_bus.h"

#include <gtest/gtest.h>

#include <chrono>
#include <thread>

namespace brdf::daemon {
namespace {

using namespace std::chrono_literals;

EventBus::Opening SnapshotOf(const std::string& name, std::optional<int> prompt_step = {}) {
  EventBus::Opening o;
  o.snapshot.set_name(name);
  if (prompt_step.has_value()) {
    v1::Prompt p;
    p.set_step_index(*prompt_step);
    p.set_text("mount the white standard");
    o.open_prompt = p;
  }
  return o;
}

v1::SessionEvent StepDone(int index) {
  v1::SessionEvent e;
  e.mutable_step_completed()->set_step_index(index);
  return e;
}

TEST(EventBusTest, LateSubscriberGetsSnapshotThenOpenPromptThenNewEvents) {
  EventBus bus(16);
  bus.Publish(7, StepDone(0));
  bus.Publish(7, StepDone(1));
  auto sub = bus.Subscribe(7, [] { return SnapshotOf("s7", 2); });
  bus.Publish(7, StepDone(3));

  auto first = sub->Next(100ms);
  ASSERT_TRUE(first.has_value());
  ASSERT_TRUE(first->has_snapshot());
  EXPECT_EQ(first->snapshot().name(), "s7");
  EXPECT_EQ(first->session_id(), "7");
  EXPECT_EQ(first->sequence(), 2u);  // the last event published before it
  auto prompt = sub->Next(100ms);
  ASSERT_TRUE(prompt.has_value());
  ASSERT_TRUE(prompt->has_prompt());
  EXPECT_EQ(prompt->prompt().step_index(), 2);
  auto next = sub->Next(100ms);
  ASSERT_TRUE(next.has_value());
  ASSERT_TRUE(next->has_step_completed());
  EXPECT_EQ(next->step_completed().step_index(), 3);
  EXPECT_EQ(next->sequence(), 3u);
  EXPECT_FALSE(sub->Next(10ms).has_value());  // nothing else
  EXPECT_FALSE(sub->ended());
}

TEST(EventBusTest, FullQueueDropsTheOldestAndNeverBlocksThePublisher) {
  EventBus bus(4);
  auto sub = bus.Subscribe(1, [] { return SnapshotOf("s1"); });
  for (int i = 0; i < 10; ++i) bus.Publish(1, StepDone(i));  // nobody reads meanwhile
  std::vector<int> seen;
  while (auto e = sub->Next(10ms)) seen.push_back(e->step_completed().step_index());
  EXPECT_EQ(seen, (std::vector<int>{6, 7, 8, 9}));  // the newest survive
  EXPECT_EQ(sub->dropped(), 7u);                    // the snapshot and events 0–5
}

TEST(EventBusTest, SubscriptionEndsAfterTheTerminalEvent) {
  EventBus bus(8);
  auto sub = bus.Subscribe(2, [] { return SnapshotOf("s2"); });
  v1::SessionEvent done;
  done.mutable_state_changed()->set_to(v1::SESSION_STATE_COMPLETED);
  bus.Publish(2, done, /*terminal=*/true);
  bus.Publish(2, StepDone(9));               // after the end: not delivered
  ASSERT_TRUE(sub->Next(50ms).has_value());  // snapshot
  auto last = sub->Next(50ms);
  ASSERT_TRUE(last.has_value());
  EXPECT_EQ(last->state_changed().to(), v1::SESSION_STATE_COMPLETED);
  EXPECT_FALSE(sub->Next(10ms).has_value());
  EXPECT_TRUE(sub->ended());
  EXPECT_EQ(bus.SubscriberCount(2), 0u);
}

TEST(EventBusTest, SubscriberOfAFinishedSessionGetsTheSnapshotAndEnds) {
  EventBus bus(8);
  auto sub = bus.Subscribe(
      3, [] { return SnapshotOf("s3", 4); }, /*already_ended=*/true);
  auto first = sub->Next(50ms);
  ASSERT_TRUE(first.has_value());
  EXPECT_TRUE(first->has_snapshot());
  EXPECT_FALSE(sub->Next(10ms).has_value());  // no prompt for an ended session
  EXPECT_TRUE(sub->ended());
}

TEST(EventBusTest, NextWakesOnPublishFromAnotherThreadAndOnClose) {
  EventBus bus(8);
  auto sub = bus.Subscribe(4, [] { return SnapshotOf("s4"); });
  ASSERT_TRUE(sub->Next(10ms).has_value());
  std::thread publisher([&bus] {
    std::this_thread::sleep_for(20ms);
    bus.Publish(4, StepDone(1));
  });
  auto e = sub->Next(5s);
  publisher.join();
  ASSERT_TRUE(e.has_value());
  EXPECT_EQ(e->step_completed().step_index(), 1);
  std::thread closer([&sub] {
    std::this_thread::sleep_for(20ms);
    sub->Close();
  });
  const auto t0 = std::chrono::steady_clock::now();
  EXPECT_FALSE(sub->Next(5s).has_value());
  closer.join();
  EXPECT_LT(std::chrono::steady_clock::now() - t0, 4s);  // woke on Close, not at the deadline
  EXPECT_TRUE(sub->ended());
}

}  // namespace
}  // namespace brdf::daemon
