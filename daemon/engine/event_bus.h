// EventBus: per-session fan-out of a session's events (state changes, prompts, step completions,
// faults) to its watchers (WatchSession streams). The executor publishes and must never wait for
// a watcher, so every subscriber has its own bounded queue: when it is full the OLDEST event is
// dropped (a slow watcher loses history, sees the gap in the sequence numbers, and still gets the
// latest state). A subscriber that joins late first receives the session's snapshot and, when
// the session awaits the operator, the open prompt, so it never misses the state it joined in.
//
// Events are the API's brdf.v1.SessionEvent messages, so the gRPC layer forwards them as they
// are. Sequence numbers are per session and increase by one per published event; a snapshot
// carries the sequence of the last event published before it.
#pragma once

#include <chrono>
#include <cstdint>
#include <deque>
#include <functional>
#include <map>
#include <memory>
#include <optional>
#include <vector>

#include "brdf/v1/brdf.pb.h"
#include "core/call_context.h"
#include "core/mutex.h"

namespace brdf::daemon {

// One watcher's queue. Thread-safe; one reader at a time.
class EventSubscription {
 public:
  explicit EventSubscription(std::size_t capacity);

  // The next event: waits up to `wait` (or until `cancel` is cancelled, or Close()). nullopt when
  // nothing arrived in time, or when the subscription has ended (ended() then says so).
  std::optional<v1::SessionEvent> Next(std::chrono::steady_clock::duration wait,
                                       const CancelToken* cancel = nullptr);

  // True once the session reached a terminal state and that event has been read, or after
  // Close(): nothing more will come.
  bool ended() const;
  // Events dropped because the queue was full.
  std::uint64_t dropped() const;
  // Stops the subscription (the watcher went away); a waiting Next returns nullopt.
  void Close();
  // `listener` is called after each event is queued (on the publisher's thread, outside the
  // queue's lock: it must not block nor call back into this subscription's Next), so a watcher
  // that holds no thread (api/pumped_stream.h) knows when to call Next(0). Replaces any before;
  // dropped at Close().
  void SetListener(std::function<void()> listener);

 private:
  friend class EventBus;
  // Appends (dropping the oldest when full); `last` marks the session's terminal event.
  void Push(v1::SessionEvent event, bool last);

  const std::size_t capacity_;
  mutable Mutex mu_;
  CondVar cv_;
  std::deque<v1::SessionEvent> queue_ GUARDED_BY(mu_);
  // The terminal event is queued: end once the queue drains.
  bool closing_ GUARDED_BY(mu_) = false;
  bool closed_ GUARDED_BY(mu_) = false;  // Close() or the terminal event was read
  std::uint64_t dropped_ GUARDED_BY(mu_) = 0;
  std::function<void()> listener_ GUARDED_BY(mu_);
};

class EventBus {
 public:
  // What a late subscriber must see first: the snapshot, and the open prompt when there is one.
  // Called under the bus's lock for that session; must not call back into the bus.
  struct Opening {
    v1::Session snapshot;
    std::optional<v1::Prompt> open_prompt;
  };
  using OpeningFn = std::function<Opening()>;

  explicit EventBus(std::size_t queue_capacity = 256);

  // Publishes an event of `session` to its current subscribers (fills session_id, sequence and
  // time). `terminal`: the session reached a terminal state; its subscriptions end after it.
  // Never blocks on a subscriber. Returns the event's sequence.
  std::uint64_t Publish(std::int64_t session, v1::SessionEvent event, bool terminal = false);

  // A new subscriber of `session`. `opening` is called atomically with respect to Publish for
  // this session, so no event falls between the snapshot and the queue. When `already_ended`
  // (the session is terminal) the subscription gets the snapshot and then ends.
  std::shared_ptr<EventSubscription> Subscribe(std::int64_t session, const OpeningFn& opening,
                                               bool already_ended = false);

  // Subscribers of `session` still registered (closed ones are pruned on the next Publish).
  std::size_t SubscriberCount(std::int64_t session) const;

 private:
  struct Channel {
    std::uint64_t sequence = 0;
    std::vector<std::weak_ptr<EventSubscription>> subscribers;
  };

  const std::size_t capacity_;
  mutable Mutex mu_;
  std::map<std::int64_t, Channel> channels_ GUARDED_BY(mu_);
};

}  // namespace brdf::daemon
