// ReadingFanout: the readings of the sessions that StreamReadings streams follow, read from the
// store once per commit for all their followers (issue 40). Without it each following stream read
// the session and a page every 200 ms whether or not anything had been committed (300 followers:
// ~3,000 queries a second over the WAL the operator's verbs read and write).
//
// How a follower uses it: Join when the stream starts (before its first page is read from the
// store), read the store page by page until a short page (caught up), then Wait for a commit newer
// than its last reading and ask After for what came: the fan-out reads the store once (the first
// follower to ask after a commit does it while the others wait for it and then take the same
// records; the commit's notice never waits for a store read) and hands every follower the readings
// after its own last id, in id order. Memory is bounded per session (`capacity` readings, the
// newest kept), not per follower: a follower that fell behind the oldest reading held gets nullopt
// and reads the store itself, as before, until it is caught up again, so a slow follower never
// holds memory nor blocks the others or the commit. Leave when the stream ends; a session nobody
// follows holds nothing.
//
// Committed is called by the session manager's reading listener (on the executor's thread): it
// only notes the id and wakes the waiters, never reads the store.
#pragma once

#include <chrono>
#include <cstddef>
#include <cstdint>
#include <deque>
#include <functional>
#include <map>
#include <optional>
#include <utility>
#include <vector>

#include "core/mutex.h"
#include "core/status.h"
#include "storage/records.h"

namespace brdf::daemon {

class ReadingFanout {
 public:
  // Reads the readings of `session` after `after_id`, at most `limit`, in id order (the store's
  // SessionReader::GetReadings).
  using ReadPage = std::function<Result<std::vector<storage::ReadingRecord>>(
      std::int64_t session, std::int64_t after_id, int limit)>;

  explicit ReadingFanout(ReadPage read, std::size_t capacity = kDefaultCapacity);
  ReadingFanout(const ReadingFanout&) = delete;
  ReadingFanout& operator=(const ReadingFanout&) = delete;

  static constexpr std::size_t kDefaultCapacity = 256;

  // A follower of `session` starts / ends. Held readings are dropped with the last follower.
  void Join(std::int64_t session);
  void Leave(std::int64_t session);

  // A reading of `session` was committed: wakes its waiting followers (no store read here).
  void Committed(std::int64_t session, std::int64_t reading_id);

  // Waits until a reading of `session` newer than `after_id` was committed (since Join), or `d`
  // passed, or Wake() was called. True when such a reading was committed.
  bool Wait(std::int64_t session, std::int64_t after_id, std::chrono::steady_clock::duration d);

  // The same for a follower that holds no thread while it waits (api/pumped_stream.h): `wake` is
  // called once a reading of `session` newer than `after_id` is committed (at once, here, when
  // one already was), or at Wake(); on the committing thread, outside the fan-out's lock. A
  // follower that left meanwhile is woken for nothing (its waker then does nothing).
  void Notify(std::int64_t session, std::int64_t after_id, std::function<void()> wake);

  // Wakes every waiting follower (the server is stopping).
  void Wake();

  // The readings of `session` after `after_id` (at most `limit`, in id order), when `after_id` is
  // not older than what is held: nullopt when the follower fell behind (or the session has no
  // follower): read the store. Reads the store once when a newer reading was committed than held.
  Result<std::optional<std::vector<storage::ReadingRecord>>> After(std::int64_t session,
                                                                   std::int64_t after_id,
                                                                   int limit);

  // Store reads made on the followers' behalf (for tests and figures).
  std::uint64_t store_reads() const;

 private:
  struct Followed {
    int followers = 0;
    std::int64_t committed = 0;  // the newest reading id committed since the first Join
    // Held: every reading of the session with id in (floor, through], oldest first (at most
    // capacity_). Unset until the first After reads the store.
    std::optional<std::int64_t> floor, through;
    std::deque<storage::ReadingRecord> held;
    // Notify's followers: the last id each has, and its waker (called and dropped at the commit
    // of a newer reading).
    std::vector<std::pair<std::int64_t, std::function<void()>>> notified;
  };
  // Reads what was committed after what is held (after `after_id` when nothing is) into the
  // session's held readings, dropping the oldest beyond capacity_. One fill at a time (fill_mu_);
  // the store is read without mu_ held.
  Status Fill(std::int64_t session, std::int64_t after_id);
  // The held readings after `after_id` (nullopt: older than what is held).
  std::optional<std::vector<storage::ReadingRecord>> TakeLocked(const Followed& f,
                                                                std::int64_t after_id,
                                                                int limit) const REQUIRES(mu_);

  const ReadPage read_;
  const std::size_t capacity_;
  Mutex fill_mu_;
  mutable Mutex mu_;
  CondVar cv_;
  std::map<std::int64_t, Followed> sessions_ GUARDED_BY(mu_);
  std::uint64_t wakes_ GUARDED_BY(mu_) = 0;
  std::uint64_t store_reads_ GUARDED_BY(mu_) = 0;
};

}  // namespace brdf::daemon
