#include "daemon/rpc/control_loop.h"

#include <spdlog/spdlog.h>
#include <sys/resource.h>
#include <sys/syscall.h>
#include <unistd.h>

#include <cerrno>
#include <cstring>

namespace brdf::daemon {
namespace {

// The control plane's threads ask for nice -5 (ahead of everything else in brdfd, the streams'
// work runs at +10: stream_registry.h). Allowed with CAP_SYS_NICE or RLIMIT_NICE ≥ 25 (the
// systemd unit's LimitNICE); otherwise they stay at 0, still ahead of the streams' work.
constexpr int kControlNice = -5;

void RaisePriority() {
  if (::setpriority(PRIO_PROCESS, static_cast<id_t>(::syscall(SYS_gettid)), kControlNice) != 0) {
    spdlog::debug("control plane: cannot raise its threads' priority (nice {}): {}; they run at 0",
                  kControlNice, std::strerror(errno));
  }
}

}  // namespace

ControlLoop::ControlLoop(int threads) : threads_(threads < 1 ? 1 : threads) {}

ControlLoop::~ControlLoop() {
  Stop();
}

void ControlLoop::AddQueue(grpc::ServerBuilder& builder) {
  queue_ = builder.AddCompletionQueue();
}

bool ControlLoop::AskIfOpen(const std::function<void()>& ask) {
  MutexLock lock(request_mu_);
  if (closing_) return false;
  ask();
  return true;
}

void ControlLoop::Start() {
  for (auto& method : methods_) method->Ask();
  for (int i = 0; i < threads_; ++i) {
    loops_.emplace_back([this] {
      RaisePriority();
      Serve();
    });
  }
}

void ControlLoop::BeginShutdown() {
  MutexLock lock(request_mu_);
  closing_ = true;
}

void ControlLoop::Stop() {
  if (stopped_) return;
  stopped_ = true;
  BeginShutdown();
  if (!queue_) return;
  queue_->Shutdown();
  if (loops_.empty()) Serve();  // never started: drain the queue here
  for (std::thread& loop : loops_) loop.join();
  loops_.clear();
}

void ControlLoop::Serve() {
  void* tag = nullptr;
  bool ok = false;
  while (queue_->Next(&tag, &ok)) {
    auto* call = static_cast<Call*>(tag);
    if (!call->Proceed(ok)) delete call;
  }
}

}  // namespace brdf::daemon
