// A server stream on gRPC's callback API whose work runs on the StreamPump (stream_pump.h): it
// holds no thread while it waits. Its body says, at each step, what to do next: write a message,
// wait (until woken, or its idle wait passed), or finish with a status. A step runs when the
// stream starts, after each write completed, when the body's own waker is called (an event, a
// commit), when the client cancels, when the idle wait passed and when the server stops; never two
// at once, and never while a write is in flight.
//
// The body is stepped only on the pump's threads and destroyed when gRPC is done with the call
// (OnDone); its StreamRegistry slot (if it opened one) times each write for the stall deadline
// as the synchronous streams' Slot::Write does.
#pragma once

#include <grpcpp/server_context.h>
#include <grpcpp/support/server_callback.h>

#include <chrono>
#include <functional>
#include <memory>
#include <utility>

#include "core/mutex.h"
#include "daemon/api/stream_pump.h"
#include "daemon/rpc/stream_registry.h"

namespace brdf::daemon {

template <class Message>
class StreamBody {
 public:
  enum class Next { kWrite, kWait, kFinish };
  virtual ~StreamBody() = default;
  // One step: kWrite with *message set, kWait (nothing to do until woken), or kFinish with
  // *status set. `wake` steps the stream again later (call it from any thread, at any time, even
  // after the stream ended: it then does nothing); bodies hand it to what they wait on.
  virtual Next Step(const std::function<void()>& wake, Message* message, grpc::Status* status) = 0;
  // The last write failed (the client went away, or the stall deadline cancelled the call): the
  // status the stream ends with.
  virtual grpc::Status WriteFailed() = 0;
  // The stream's slot once opened (writes are timed through it), else null.
  virtual StreamRegistry::Slot* slot() = 0;
};

template <class Message>
class PumpedStream final : public grpc::ServerWriteReactor<Message> {
 public:
  // Starts stepping `body` on `pump`; a waiting body is stepped again at least every `idle_wait`.
  PumpedStream(StreamPump& pump, std::unique_ptr<StreamBody<Message>> body,
               std::chrono::steady_clock::duration idle_wait)
      : state_(std::make_shared<State>(pump, std::move(body), idle_wait, this)) {
    state_->stop_waker = pump.AddStopWaker(Waker(state_));
    State::Wake(state_);
  }

  void OnWriteDone(bool ok) override {
    {
      MutexLock lock(state_->mu);
      if (StreamRegistry::Slot* slot = state_->body->slot()) slot->EndWrite();
      state_->write_failed = !ok;
      state_->busy = false;
    }
    State::Wake(state_);
  }
  void OnCancel() override { State::Wake(state_); }
  void OnDone() override {
    state_->pump.RemoveStopWaker(state_->stop_waker);
    {
      MutexLock lock(state_->mu);
      state_->reactor = nullptr;
    }
    // The body (its slot, its subscription) goes now, not with the last timer that holds state_.
    std::unique_ptr<StreamBody<Message>> body;
    {
      MutexLock lock(state_->mu);
      body = std::move(state_->body);
    }
    body.reset();
    delete this;
  }

 private:
  struct State {
    State(StreamPump& p, std::unique_ptr<StreamBody<Message>> b,
          std::chrono::steady_clock::duration idle, PumpedStream* r)
        : pump(p), idle_wait(idle), body(std::move(b)), reactor(r) {}

    // Steps the stream soon unless a step is queued or running or a write is in flight (then
    // once more after it).
    static void Wake(const std::shared_ptr<State>& self) {
      {
        MutexLock lock(self->mu);
        if (self->finished) return;
        if (self->busy) {
          self->again = true;
          return;
        }
        self->busy = true;
      }
      self->pump.Post([self] { Run(self); });
    }

    // One step on a pump thread.
    static void Run(const std::shared_ptr<State>& self) {
      MutexLock lock(self->mu);
      self->again = false;
      typename StreamBody<Message>::Next next;
      grpc::Status status;
      if (self->write_failed) {
        next = StreamBody<Message>::Next::kFinish;
        status = self->body->WriteFailed();
      } else {
        lock.Unlock();  // the body may read the store; wakes meanwhile set `again`
        next = self->body->Step(Waker(self), &self->message, &status);
        lock.Lock();
      }
      PumpedStream* reactor = self->reactor;
      switch (next) {
        case StreamBody<Message>::Next::kWrite:
          if (StreamRegistry::Slot* slot = self->body->slot()) slot->BeginWrite();
          lock.Unlock();
          reactor->StartWrite(&self->message);  // busy until OnWriteDone
          return;
        case StreamBody<Message>::Next::kFinish:
          self->finished = true;
          lock.Unlock();
          reactor->Finish(status);
          return;
        case StreamBody<Message>::Next::kWait:
          break;
      }
      self->busy = false;
      const bool again = std::exchange(self->again, false);
      const bool arm = !self->timer_armed;
      self->timer_armed = true;
      lock.Unlock();
      if (again) Wake(self);
      if (arm) {
        self->pump.PostAfter(self->idle_wait, [self] {
          {
            MutexLock timer_lock(self->mu);
            self->timer_armed = false;
          }
          Wake(self);
        });
      }
    }

    Mutex mu;
    StreamPump& pump;
    const std::chrono::steady_clock::duration idle_wait;
    std::uint64_t stop_waker = 0;
    std::unique_ptr<StreamBody<Message>> body;  // gone at OnDone
    PumpedStream* reactor;                      // null after OnDone
    Message message;                            // the write in flight
    bool busy = false;                          // a step queued or running, or a write in flight
    bool again = false;                         // woken while busy: step once more after
    bool timer_armed = false;                   // an idle-wait timer is pending
    bool write_failed = false;
    bool finished = false;  // Finish called: nothing more
  };

  // A waker that holds the state, not the reactor: safe after the stream ended.
  static std::function<void()> Waker(const std::shared_ptr<State>& state) {
    return [weak = std::weak_ptr<State>(state)] {
      if (std::shared_ptr<State> s = weak.lock()) State::Wake(s);
    };
  }

  std::shared_ptr<State> state_;
};

}  // namespace brdf::daemon
