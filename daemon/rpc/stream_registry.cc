#include "daemon/rpc/stream_registry.h"

#include <spdlog/spdlog.h>

#include <algorithm>

#include "daemon/rpc/thread_priority.h"

namespace brdf::daemon {
namespace {

// Room beyond the stream caps in the synchronous pool: the analysts' unary calls and the pollers.
constexpr int kUnaryThreads = 64;

std::int64_t NowNs() {
  return std::chrono::duration_cast<std::chrono::nanoseconds>(
             std::chrono::steady_clock::now().time_since_epoch())
      .count();
}

grpc::Status CapReached(std::string_view rpc, const std::string& who, int cap,
                        const std::string& key) {
  return grpc::Status(grpc::StatusCode::RESOURCE_EXHAUSTED,
                      std::string(rpc) + ": " + who + " already hold" +
                          (who.rfind("token", 0) == 0 ? "s " : " ") + std::to_string(cap) +
                          " open stream(s), the most [server] " + key +
                          " allows; close a stream first (or raise " + key + ")");
}

}  // namespace

struct StreamRegistry::Entry {
  grpc::ServerContextBase* context = nullptr;
  std::string rpc;
  std::string who;    // for the log: "token \"lab-pc\"" or "a client without a token"
  std::string token;  // the token's name, "" without a token
  Role role = Role::kAnalyst;
  bool authenticated = false;
  std::atomic<std::int64_t> write_since_ns{0};  // 0: no write waiting
  bool cancelled = false;
};

int ServerThreadCap(const ServerConfig& config) {
  return config.max_streams_analyst + config.max_streams_operator +
         config.max_streams_unauthenticated + kUnaryThreads;
}

StreamRegistry::StreamRegistry(const ServerConfig& config, bool tokens_configured)
    : limits_(config),
      per_token_(tokens_configured),
      stall_timeout_(std::chrono::seconds(config.stream_stall_timeout_s)),
      budget_(config.memory_budget_mb),
      work_(static_cast<int>(std::max(1U, std::thread::hardware_concurrency() / 2))) {
  watchdog_ = std::thread([this] { Watchdog(); });
}

StreamRegistry::~StreamRegistry() {
  {
    MutexLock lock(mu_);
    stop_ = true;
  }
  stop_cv_.NotifyAll();
  watchdog_.join();
}

grpc::Status StreamRegistry::Open(grpc::ServerContextBase& context, const Caller* caller,
                                  std::string_view rpc, std::unique_ptr<Slot>* slot,
                                  bool computes) {
  {
    MutexLock lock(mu_);
    auto entry = std::make_unique<Entry>();
    entry->context = &context;
    entry->rpc = std::string(rpc);
    if (caller == nullptr) {
      if (unauthenticated_open_ >= limits_.max_streams_unauthenticated) {
        return CapReached(rpc, "calls without a token", limits_.max_streams_unauthenticated,
                          "max_streams_unauthenticated");
      }
      ++unauthenticated_open_;
      entry->who = "a client without a token";
    } else {
      const bool op = caller->role == Role::kOperator;
      int& role_open = op ? operator_open_ : analyst_open_;
      const int role_cap = op ? limits_.max_streams_operator : limits_.max_streams_analyst;
      if (per_token_) {
        const int held = per_token_open_.count(caller->name) ? per_token_open_[caller->name] : 0;
        if (held >= limits_.max_streams_per_token) {
          return CapReached(rpc, "token \"" + caller->name + "\"", limits_.max_streams_per_token,
                            "max_streams_per_token");
        }
      }
      if (role_open >= role_cap) {
        return CapReached(rpc, std::string(op ? "operator" : "analyst") + " tokens together",
                          role_cap, op ? "max_streams_operator" : "max_streams_analyst");
      }
      ++role_open;
      if (per_token_) ++per_token_open_[caller->name];
      entry->who = "token \"" + caller->name + "\"";
      entry->token = caller->name;
      entry->role = caller->role;
      entry->authenticated = true;
    }
    const std::uint64_t id = next_id_++;
    Entry* raw = entry.get();
    entries_.emplace(id, std::move(entry));
    slot->reset(new Slot(this, id, raw, computes));
  }
  if (computes) (*slot)->holding_ = AcquireWork(context, (*slot)->entry_->token);
  return grpc::Status::OK;
}

bool StreamRegistry::AcquireWork(const grpc::ServerContextBase& context, const std::string& token) {
  if (!work_.Acquire(token, [&context] { return context.IsCancelled(); })) return false;
  (void)SetThisThreadNice(kStreamNice);  // the work runs below the control plane and the transport
  return true;
}

void StreamRegistry::Release(std::uint64_t id) {
  MutexLock lock(mu_);
  auto it = entries_.find(id);
  if (it == entries_.end()) return;
  const Entry& e = *it->second;
  if (!e.authenticated) {
    --unauthenticated_open_;
  } else {
    (e.role == Role::kOperator ? operator_open_ : analyst_open_)--;
    if (per_token_ && --per_token_open_[e.token] <= 0) per_token_open_.erase(e.token);
  }
  entries_.erase(it);
  budget_.AskTrim();
}

int StreamRegistry::open() const {
  MutexLock lock(mu_);
  return static_cast<int>(entries_.size());
}

void StreamRegistry::Watchdog() {
  const auto period = std::clamp<std::chrono::steady_clock::duration>(
      stall_timeout_ / 4, std::chrono::milliseconds(50), std::chrono::seconds(1));
  MutexLock lock(mu_);
  while (!stop_) {
    stop_cv_.WaitFor(mu_, period);
    lock.Unlock();  // a trim takes milliseconds: streams open and close meanwhile
    budget_.TrimIfDue();
    lock.Lock();
    const std::int64_t now = NowNs();
    const std::int64_t limit =
        std::chrono::duration_cast<std::chrono::nanoseconds>(stall_timeout_).count();
    for (auto& [id, entry] : entries_) {
      const std::int64_t since = entry->write_since_ns.load();
      if (entry->cancelled || since == 0 || now - since < limit) continue;
      entry->cancelled = true;
      stalled_.fetch_add(1);
      spdlog::info(
          "{}: cancelled a stream of {}: its client read nothing for {} s "
          "([server] stream_stall_timeout_s)",
          entry->rpc, entry->who, limits_.stream_stall_timeout_s);
      entry->context->TryCancel();
    }
  }
}

StreamRegistry::Slot::~Slot() {
  Close();
  reservations_.clear();
  registry_->Release(id_);
}

void StreamRegistry::Slot::Close() {
  if (!holding_) return;
  registry_->work_.Release(entry_->token);
  holding_ = false;
  // Back to 0 (where allowed) before the thread writes or waits: a thread of gRPC's pool polls
  // the transport for every connection, the control plane's too (thread_priority.h).
  (void)SetThisThreadNice(0);
}

grpc::Status StreamRegistry::Slot::Reserve(std::uint64_t bytes) {
  std::unique_ptr<MemoryBudget::Reservation> reservation;
  grpc::Status st = registry_->budget_.Reserve(entry_->rpc, bytes, &reservation);
  if (st.ok()) reservations_.push_back(std::move(reservation));
  return st;
}

bool StreamRegistry::Slot::Work() {
  if (!holding_) holding_ = registry_->AcquireWork(*entry_->context, entry_->token);
  return holding_;
}

void StreamRegistry::Slot::BeginWrite() {
  Close();
  entry_->write_since_ns.store(NowNs());
}

void StreamRegistry::Slot::EndWrite() {
  entry_->write_since_ns.store(0);
  if (computes_) holding_ = registry_->AcquireWork(*entry_->context, entry_->token);
}

}  // namespace brdf::daemon
