#include "daemon/engine/event_bus.h"

#include <algorithm>
#include <chrono>
#include <utility>

#include "daemon/wire/values.h"

namespace brdf::daemon {

EventSubscription::EventSubscription(std::size_t capacity)
    : capacity_(std::max<std::size_t>(capacity, 2)) {}

void EventSubscription::Push(v1::SessionEvent event, bool last) {
  std::function<void()> listener;
  {
    MutexLock lock(mu_);
    if (closed_ || closing_) return;
    if (queue_.size() >= capacity_) {
      queue_.pop_front();
      ++dropped_;
    }
    queue_.push_back(std::move(event));
    if (last) closing_ = true;
    listener = listener_;
  }
  cv_.NotifyAll();
  if (listener) listener();
}

void EventSubscription::SetListener(std::function<void()> listener) {
  MutexLock lock(mu_);
  if (!closed_) listener_ = std::move(listener);
}

std::optional<v1::SessionEvent> EventSubscription::Next(std::chrono::steady_clock::duration wait,
                                                        const CancelToken* cancel) {
  MutexLock lock(mu_);
  const auto until = std::chrono::steady_clock::now() + wait;
  // With a cancel token, wake up now and then to look at it (the token has its own condition
  // variable, which cannot wake this one).
  constexpr auto kCancelPoll = std::chrono::milliseconds(50);
  while (queue_.empty() && !closed_) {
    if (closing_) {  // the terminal event was read: nothing more will come
      closed_ = true;
      break;
    }
    if (cancel != nullptr && cancel->cancelled()) return std::nullopt;
    const auto now = std::chrono::steady_clock::now();
    if (now >= until) return std::nullopt;
    auto step = until - now;
    if (cancel != nullptr) step = std::min<std::chrono::steady_clock::duration>(step, kCancelPoll);
    cv_.WaitFor(mu_, step);
  }
  if (queue_.empty()) return std::nullopt;
  v1::SessionEvent event = std::move(queue_.front());
  queue_.pop_front();
  if (queue_.empty() && closing_) closed_ = true;
  return event;
}

bool EventSubscription::ended() const {
  MutexLock lock(mu_);
  return closed_;
}

std::uint64_t EventSubscription::dropped() const {
  MutexLock lock(mu_);
  return dropped_;
}

void EventSubscription::Close() {
  {
    MutexLock lock(mu_);
    closed_ = true;
    queue_.clear();
    listener_ = nullptr;
  }
  cv_.NotifyAll();
}

EventBus::EventBus(std::size_t queue_capacity) : capacity_(queue_capacity) {}

std::uint64_t EventBus::Publish(std::int64_t session, v1::SessionEvent event, bool terminal) {
  MutexLock lock(mu_);
  Channel& channel = channels_[session];
  event.set_session_id(std::to_string(session));
  event.set_sequence(++channel.sequence);
  if (!event.has_time()) *event.mutable_time() = NowTimestamp();
  auto& subs = channel.subscribers;
  for (auto it = subs.begin(); it != subs.end();) {
    std::shared_ptr<EventSubscription> sub = it->lock();
    if (sub == nullptr || sub->ended()) {
      it = subs.erase(it);
      continue;
    }
    sub->Push(event, terminal);  // never blocks: drops the subscriber's oldest event when full
    ++it;
  }
  if (terminal) subs.clear();  // every subscription ends with this event
  return channel.sequence;
}

std::shared_ptr<EventSubscription> EventBus::Subscribe(std::int64_t session,
                                                       const OpeningFn& opening,
                                                       bool already_ended) {
  auto sub = std::make_shared<EventSubscription>(capacity_);
  MutexLock lock(mu_);
  Channel& channel = channels_[session];
  Opening first = opening();
  v1::SessionEvent snapshot;
  snapshot.set_session_id(std::to_string(session));
  snapshot.set_sequence(channel.sequence);
  *snapshot.mutable_time() = NowTimestamp();
  *snapshot.mutable_snapshot() = std::move(first.snapshot);
  const bool has_prompt = first.open_prompt.has_value() && !already_ended;
  sub->Push(std::move(snapshot), already_ended);
  if (has_prompt) {
    v1::SessionEvent prompt;
    prompt.set_session_id(std::to_string(session));
    prompt.set_sequence(channel.sequence);
    *prompt.mutable_time() = NowTimestamp();
    *prompt.mutable_prompt() = std::move(*first.open_prompt);
    sub->Push(std::move(prompt), false);
  }
  if (!already_ended) channel.subscribers.push_back(sub);
  return sub;
}

std::size_t EventBus::SubscriberCount(std::int64_t session) const {
  MutexLock lock(mu_);
  auto it = channels_.find(session);
  if (it == channels_.end()) return 0;
  std::size_t n = 0;
  for (const auto& w : it->second.subscribers) {
    auto s = w.lock();
    if (s != nullptr && !s->ended()) ++n;
  }
  return n;
}

}  // namespace brdf::daemon
