#include "daemon/rpc/control_loop.h"

#include <spdlog/spdlog.h>

#include <cerrno>
#include <cstring>

#include "daemon/rpc/thread_priority.h"

namespace brdf::daemon {
namespace {

void RaisePriority() {
  if (SetThisThreadNiceAndSlice(kControlNice, kControlSlice)) return;
  spdlog::debug("control plane: cannot raise its threads' priority (nice {}): {}; they run at 0",
                kControlNice, std::strerror(errno));
  (void)SetThisThreadNiceAndSlice(0, kControlSlice);
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
      NameThisThread("ctl-plane");
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
