// The followers' fan-out (daemon/api/stream_readings_fanout.h): every follower gets every reading
// of its session in id order with one store read per commit for all of them; a follower that fell
// behind what is held is told to read the store (memory bounded per session, not per follower); a
// store read in progress never holds up a commit's notice; a follower with nothing new reads
// nothing.
#include <gtest/gtest.h>

#include <atomic>
#include <chrono>
#include <condition_variable>
#include <mutex>
#include <thread>
#include <vector>

#include "daemon/api/stream_readings_fanout.h"

namespace brdf::daemon {
namespace {

using namespace std::chrono_literals;

// The readings of every session, as the store holds them (ids shared across sessions).
class FakeStore {
 public:
  std::int64_t Commit(std::int64_t session) {
    std::lock_guard<std::mutex> lock(mu_);
    storage::ReadingRecord r;
    r.id = static_cast<std::int64_t>(readings_.size()) + 1;
    r.session_id = session;
    readings_.push_back(r);
    return r.id;
  }
  Result<std::vector<storage::ReadingRecord>> Read(std::int64_t session, std::int64_t after_id,
                                                   int limit) {
    std::lock_guard<std::mutex> lock(mu_);
    ++reads_;
    std::vector<storage::ReadingRecord> out;
    for (const storage::ReadingRecord& r : readings_) {
      if (static_cast<int>(out.size()) == limit) break;
      if (r.session_id == session && r.id > after_id) out.push_back(r);
    }
    return out;
  }
  int reads() {
    std::lock_guard<std::mutex> lock(mu_);
    return reads_;
  }
  ReadingFanout::ReadPage Reader() {
    return [this](std::int64_t s, std::int64_t after, int limit) { return Read(s, after, limit); };
  }

 private:
  std::mutex mu_;
  std::vector<storage::ReadingRecord> readings_;
  int reads_ = 0;
};

// A follower as StreamReadings is one: the store until caught up, then Wait and After (the store
// again when After says it fell behind). Returns the ids it got, in the order it got them.
std::vector<std::int64_t> Follow(ReadingFanout& fanout, FakeStore& store, std::int64_t session,
                                 std::size_t want, std::atomic<int>* own_store_reads) {
  std::vector<std::int64_t> got;
  std::int64_t last = 0;
  auto take = [&](const std::vector<storage::ReadingRecord>& page) {
    for (const storage::ReadingRecord& r : page) {
      got.push_back(r.id);
      last = r.id;
    }
  };
  take(*store.Read(session, last, 256));
  const auto give_up = std::chrono::steady_clock::now() + 20s;
  while (got.size() < want && std::chrono::steady_clock::now() < give_up) {
    if (!fanout.Wait(session, last, 100ms)) continue;
    Result<std::optional<std::vector<storage::ReadingRecord>>> held =
        fanout.After(session, last, 256);
    if (!held.ok()) break;
    if (held->has_value()) {
      take(**held);
    } else {
      ++*own_store_reads;
      take(*store.Read(session, last, 256));
    }
  }
  return got;
}

TEST(ReadingFanout, EveryFollowerGetsEveryReadingInOrderWithOneStoreReadPerCommit) {
  FakeStore store;
  ReadingFanout fanout(store.Reader());
  constexpr std::int64_t kSession = 7, kOther = 8;
  constexpr std::size_t kReadings = 120;
  constexpr int kFollowers = 6;
  std::vector<std::vector<std::int64_t>> got(kFollowers);
  std::atomic<int> own_reads{0};
  std::vector<std::thread> followers;
  for (int i = 0; i < kFollowers; ++i) fanout.Join(kSession);
  for (int i = 0; i < kFollowers; ++i) {
    followers.emplace_back([&, i] {
      got[static_cast<std::size_t>(i)] = Follow(fanout, store, kSession, kReadings, &own_reads);
    });
  }
  std::vector<std::int64_t> committed;
  for (std::size_t n = 0; n < kReadings; ++n) {
    (void)store.Commit(kOther);  // another session's reading: never handed to these followers
    const std::int64_t id = store.Commit(kSession);
    committed.push_back(id);
    fanout.Committed(kSession, id);
    if (n % 10 == 0) std::this_thread::sleep_for(2ms);
  }
  for (std::thread& t : followers) t.join();
  for (const std::vector<std::int64_t>& ids : got) EXPECT_EQ(ids, committed);
  // A follower reads the store itself at most once, when it caught up before the first fill
  // (whose floor was a later follower's last id); never again with 256 readings held.
  EXPECT_LE(own_reads.load(), kFollowers);
  // One read per commit at most (several commits between two reads share one), not one per
  // follower and commit; the followers' first pages are their own.
  EXPECT_GT(fanout.store_reads(), 0u);
  EXPECT_LE(fanout.store_reads(), kReadings);
  EXPECT_LE(store.reads(), static_cast<int>(kReadings) + 2 * kFollowers);
  for (int i = 0; i < kFollowers; ++i) fanout.Leave(kSession);
}

TEST(ReadingFanout, AFollowerBehindWhatIsHeldIsToldToReadTheStore) {
  FakeStore store;
  ReadingFanout fanout(store.Reader(), /*capacity=*/4);
  constexpr std::int64_t kSession = 1;
  fanout.Join(kSession);  // the quick follower
  fanout.Join(kSession);  // the slow one: it reads nothing while 10 readings come
  std::int64_t quick = 0;
  for (int n = 0; n < 10; ++n) {
    const std::int64_t id = store.Commit(kSession);
    fanout.Committed(kSession, id);
    ASSERT_TRUE(fanout.Wait(kSession, quick, 1s));
    Result<std::optional<std::vector<storage::ReadingRecord>>> held =
        fanout.After(kSession, quick, 256);
    ASSERT_TRUE(held.ok());
    ASSERT_TRUE(held->has_value());
    ASSERT_EQ((*held)->size(), 1u);
    EXPECT_EQ((*held)->front().id, id);
    quick = id;
  }
  // At most 4 readings are held for the session, whoever lags: the slow follower (last id 0, then
  // 5) gets nullopt, reads the store, and from the newest held on takes them from the fan-out.
  Result<std::optional<std::vector<storage::ReadingRecord>>> slow = fanout.After(kSession, 0, 256);
  ASSERT_TRUE(slow.ok());
  EXPECT_FALSE(slow->has_value());
  slow = fanout.After(kSession, 5, 256);
  ASSERT_TRUE(slow.ok());
  EXPECT_FALSE(slow->has_value());
  slow = fanout.After(kSession, 7, 256);
  ASSERT_TRUE(slow.ok());
  ASSERT_TRUE(slow->has_value());
  ASSERT_EQ((*slow)->size(), 3u);
  EXPECT_EQ((*slow)->front().id, 8);
  EXPECT_EQ((*slow)->back().id, 10);
  // More committed at once than one fill holds: nullopt (the store), never a short page that
  // would end a stream early.
  for (int n = 0; n < 6; ++n) fanout.Committed(kSession, store.Commit(kSession));
  slow = fanout.After(kSession, 10, 256);
  ASSERT_TRUE(slow.ok());
  EXPECT_FALSE(slow->has_value());
  fanout.Leave(kSession);
  fanout.Leave(kSession);
}

TEST(ReadingFanout, AFollowerWithNothingNewWaitsAndReadsNothing) {
  FakeStore store;
  ReadingFanout fanout(store.Reader());
  fanout.Join(3);
  const auto begin = std::chrono::steady_clock::now();
  EXPECT_FALSE(fanout.Wait(3, 0, 150ms));
  EXPECT_GE(std::chrono::steady_clock::now() - begin, 140ms);
  Result<std::optional<std::vector<storage::ReadingRecord>>> held = fanout.After(3, 0, 256);
  ASSERT_TRUE(held.ok());
  ASSERT_TRUE(held->has_value());
  EXPECT_TRUE((*held)->empty());
  EXPECT_EQ(store.reads(), 0);
  // A commit of another session does not wake it; Wake (the server stops) does.
  fanout.Committed(4, store.Commit(4));
  EXPECT_FALSE(fanout.Wait(3, 0, 50ms));
  std::thread waker([&] {
    std::this_thread::sleep_for(50ms);
    fanout.Wake();
  });
  const auto waiting = std::chrono::steady_clock::now();
  EXPECT_FALSE(fanout.Wait(3, 0, 10s));
  EXPECT_LT(std::chrono::steady_clock::now() - waiting, 5s);
  waker.join();
  // The last follower gone, nothing is held: After says to read the store.
  fanout.Leave(3);
  held = fanout.After(3, 0, 256);
  ASSERT_TRUE(held.ok());
  EXPECT_FALSE(held->has_value());
}

TEST(ReadingFanout, AStoreReadInProgressNeverHoldsUpACommitsNotice) {
  std::mutex mu;
  std::condition_variable cv;
  bool reading = false, release = false;
  FakeStore store;
  ReadingFanout fanout([&](std::int64_t s, std::int64_t after, int limit) {
    std::unique_lock<std::mutex> lock(mu);
    reading = true;
    cv.notify_all();
    cv.wait(lock, [&] { return release; });
    return store.Read(s, after, limit);
  });
  fanout.Join(1);
  fanout.Committed(1, store.Commit(1));
  std::thread follower([&] { (void)fanout.After(1, 0, 256); });
  {
    std::unique_lock<std::mutex> lock(mu);
    ASSERT_TRUE(cv.wait_for(lock, 5s, [&] { return reading; }));
  }
  // The follower is inside its store read: the executor's notice of the next commit returns.
  const auto begin = std::chrono::steady_clock::now();
  fanout.Committed(1, store.Commit(1));
  EXPECT_LT(std::chrono::steady_clock::now() - begin, 1s);
  {
    std::lock_guard<std::mutex> lock(mu);
    release = true;
  }
  cv.notify_all();
  follower.join();
  fanout.Leave(1);
}

}  // namespace
}  // namespace brdf::daemon
