// The streams brdfd holds open (WatchSession, StreamReadings, Export, InterpolateBatch, the
// health service's Watch), with their caps and their stall deadline.
//
// Caps ([server] in the configuration, config.h): per token (max_streams_per_token), per role,
// all tokens of the role together (max_streams_analyst, max_streams_operator), and for calls
// without a token (max_streams_unauthenticated). Open() refuses a stream beyond a cap with
// RESOURCE_EXHAUSTED naming the cap and its key. With no tokens configured every caller is the
// operator "anonymous" and only the role cap applies. Each open stream on gRPC's synchronous pool
// (Export, InterpolateBatch, RenderAppearance, health Watch, reflection) holds one of its
// threads, which server.cc sizes above the caps' sum (ServerThreadCap): the streams cannot
// exhaust it, and the control plane is not on it at all (control_loop.h). WatchSession and
// StreamReadings hold none while they wait (api/stream_pump.h).
//
// Bounded work: a stream that computes what it sends (Export, InterpolateBatch: opened with
// `computes`; RenderAppearance takes one with Slot::Work once it knows it must render) works only
// while it holds one of a few work permits (one per two cores), and gives its permit back while a
// write waits for the client. Permits are shared fairly between tokens (work_permits.h): a free
// one goes to the waiting token that holds the fewest, so one analyst's hundred exports do not
// keep another's one waiting behind them. A thousand exports then take turns on the
// cores instead of all running at once. A stream's thread runs at nice 10 while it holds a permit,
// below the control plane's threads and Interpolate's loop, which get a core when they need one,
// and is back at 0 (where allowed) when it gives the permit back, before it writes or waits: a
// thread of gRPC's pool polls the transport for every connection (thread_priority.h).
//
// Memory: a heavy stream reserves what it will hold from the memory budget (Slot::Reserve,
// memory_budget.h) once it knows its request; the watchdog gives freed memory back to the system
// after streams end (MemoryBudget::TrimIfDue).
//
// Stall deadline (stream_stall_timeout_s): a stream writes through its Slot; a write that has
// waited that long (the client read nothing meanwhile: HTTP/2 flow control holds the message)
// gets the call cancelled by the registry's watchdog thread, so the write fails, the handler
// returns and frees what it held (an export's whole file, ~35 MB for MERL).
#pragma once

#include <grpcpp/server_context.h>
#include <grpcpp/support/status.h>

#include <atomic>
#include <chrono>
#include <cstdint>
#include <map>
#include <memory>
#include <string>
#include <string_view>
#include <thread>
#include <vector>

#include "core/mutex.h"
#include "daemon/config/config.h"
#include "daemon/rpc/auth.h"
#include "daemon/rpc/memory_budget.h"
#include "daemon/rpc/work_permits.h"

namespace brdf::daemon {

// The synchronous pool's thread cap for these caps: their sum plus room for the short unary calls
// the pool also serves (ValidatePlan, GetSession, ListSessions) and its pollers.
int ServerThreadCap(const ServerConfig& config);

class StreamRegistry {
 public:
  struct Entry;

  // An open stream's place; released by its destructor. Write through it.
  class Slot {
   public:
    ~Slot();
    Slot(const Slot&) = delete;
    Slot& operator=(const Slot&) = delete;

    // writer->Write(message), timed for the stall deadline: false when the client went away or
    // the stream was cancelled for not reading.
    template <class Writer, class Message>
    bool Write(Writer* writer, const Message& message) {
      BeginWrite();
      const bool ok = writer->Write(message);
      EndWrite();
      return ok;
    }
    // The same for a message the stream builds again: *message is emptied (its memory freed) after
    // the write serialized it and before the wait for the next work permit, so a stream waiting
    // its turn holds no message (issue 40: a hundred waiting exports or batches held one each).
    template <class Writer, class Message>
    bool WriteAndRelease(Writer* writer, Message* message) {
      BeginWrite();
      const bool ok = writer->Write(*message);
      *message = Message();
      EndWrite();
      return ok;
    }
    // Releases the work permit (if any) before it goes away.
    void Close();
    // Reserves `bytes` of the memory budget (memory_budget.h) for the rest of the stream: OK, or
    // RESOURCE_EXHAUSTED naming [server] memory_budget_mb. A stream may reserve more as it learns
    // what it needs; all is given back when the stream ends.
    grpc::Status Reserve(std::uint64_t bytes);
    // Takes a work permit now if it holds none: for a call that learns only after Open whether it
    // has work to do (RenderAppearance, on a cache miss). Waits for one; false when the call was
    // cancelled meanwhile.
    bool Work();
    // What Write does around writer->Write, for a stream that writes asynchronously (gRPC's
    // callback API: BeginWrite before StartWrite, EndWrite in OnWriteDone): the write is timed for
    // the stall deadline; BeginWrite gives the work permit back, EndWrite takes one again (waits:
    // not for a callback stream that computes).
    void BeginWrite();
    void EndWrite();

   private:
    friend class StreamRegistry;
    Slot(StreamRegistry* registry, std::uint64_t id, Entry* entry, bool computes)
        : registry_(registry), id_(id), entry_(entry), computes_(computes) {}
    StreamRegistry* registry_;
    std::uint64_t id_;
    Entry* entry_;
    const bool computes_;
    bool holding_ = false;  // a work permit
    std::vector<std::unique_ptr<MemoryBudget::Reservation>> reservations_;
  };

  // `tokens_configured`: false when the API is open (auth disabled): no per-token cap. Starts
  // the watchdog thread.
  StreamRegistry(const ServerConfig& config, bool tokens_configured);
  ~StreamRegistry();  // stops the watchdog; every Slot must be gone
  StreamRegistry(const StreamRegistry&) = delete;
  StreamRegistry& operator=(const StreamRegistry&) = delete;

  // Admits a stream of `rpc` for `caller` (nullptr: a call without a token) on `context`: OK with
  // *slot set, or RESOURCE_EXHAUSTED naming the cap that is full and its configuration key. With
  // `computes`, waits for a work permit first (returns without one if the call is cancelled).
  grpc::Status Open(grpc::ServerContextBase& context, const Caller* caller, std::string_view rpc,
                    std::unique_ptr<Slot>* slot, bool computes = false);

  // The heavy calls' memory budget ([server] memory_budget_mb).
  MemoryBudget& budget() { return budget_; }

  // Work permits: one per two cores, at least one.
  int work_permits() const { return work_.permits(); }

  // Streams open now, and streams cancelled for not reading since the start.
  int open() const;
  std::uint64_t stalled() const { return stalled_.load(); }

 private:
  void Release(std::uint64_t id);
  // Waits for a work permit for a stream of `token` ("": without a token); false: `context` was
  // cancelled meanwhile.
  bool AcquireWork(const grpc::ServerContextBase& context, const std::string& token);
  void Watchdog();

  const ServerConfig limits_;
  const bool per_token_;
  const std::chrono::steady_clock::duration stall_timeout_;

  mutable Mutex mu_;
  CondVar stop_cv_;
  bool stop_ GUARDED_BY(mu_) = false;
  std::uint64_t next_id_ GUARDED_BY(mu_) = 1;
  std::map<std::uint64_t, std::unique_ptr<Entry>> entries_ GUARDED_BY(mu_);
  std::map<std::string, int> per_token_open_ GUARDED_BY(mu_);
  int analyst_open_ GUARDED_BY(mu_) = 0;
  int operator_open_ GUARDED_BY(mu_) = 0;
  int unauthenticated_open_ GUARDED_BY(mu_) = 0;
  std::atomic<std::uint64_t> stalled_{0};
  MemoryBudget budget_;
  WorkPermits work_;
  std::thread watchdog_;
};

}  // namespace brdf::daemon
