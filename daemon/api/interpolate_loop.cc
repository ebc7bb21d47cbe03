#include "daemon/api/interpolate_loop.h"

#include <grpcpp/server_context.h>
#include <grpcpp/support/async_unary_call.h>
#include <pthread.h>
#include <sched.h>
#include <spdlog/spdlog.h>
#include <unistd.h>

#include <cstring>
#include <optional>
#include <utility>

#include "daemon/rpc/thread_priority.h"

namespace brdf::daemon {
namespace {

// Calls asked for ahead on each queue: calls that arrive while the loop is busy are matched to
// these at once rather than parked in gRPC's list of unmatched calls.
constexpr int kRequestsAhead = 8;

// Runs the calling thread on `cpu` only.
void PinToCpu(int cpu) {
  cpu_set_t set;
  CPU_ZERO(&set);
  CPU_SET(cpu, &set);
  if (int error = pthread_setaffinity_np(pthread_self(), sizeof(set), &set); error != 0) {
    spdlog::warn(
        "Interpolate loop: cannot pin to CPU {} ({}); it runs unpinned. Check [server] "
        "interpolate_cpus against the CPUs brdfd may use (taskset -p {}, the service's "
        "CPUAffinity)",
        cpu, std::strerror(error), ::getpid());
  }
}

}  // namespace

// One Interpolate call, from the request's arrival to the reply's completion; its own tag.
struct InterpolateLoop::Call {
  explicit Call(grpc::ServerCompletionQueue* q) : queue(q), responder(&context) {}

  grpc::ServerCompletionQueue* queue;
  grpc::ServerContext context;
  v1::InterpolateRequest request;
  v1::InterpolateResponse response;
  grpc::ServerAsyncResponseWriter<v1::InterpolateResponse> responder;
  bool finishing = false;  // the reply is queued: the next event is its completion
};

InterpolateLoop::InterpolateLoop(InterpolationService& service, int threads, std::vector<int> cpus)
    : service_(service), threads_(threads < 1 ? 1 : threads), cpus_(std::move(cpus)) {}

InterpolateLoop::~InterpolateLoop() {
  Stop();
}

void InterpolateLoop::AddQueues(grpc::ServerBuilder& builder) {
  for (int i = 0; i < threads_; ++i) queues_.push_back(builder.AddCompletionQueue());
}

void InterpolateLoop::Start() {
  for (auto& queue : queues_) {
    for (int i = 0; i < kRequestsAhead; ++i) Request(queue.get());
  }
  // Analysts' calls: below the control plane when the cores are busy (rpc/thread_priority.h).
  slow_lane_ = std::thread([this] {
    NameThisThread("interp-slow");
    (void)SetThisThreadNice(kInterpolateNice);
    SlowLane();
  });
  for (std::size_t i = 0; i < queues_.size(); ++i) {
    const int cpu = cpus_.empty() ? -1 : cpus_[i % cpus_.size()];
    loops_.emplace_back([this, q = queues_[i].get(), cpu] {
      if (cpu >= 0) PinToCpu(cpu);
      NameThisThread("interp-loop");
      (void)SetThisThreadNice(kInterpolateNice);
      Serve(q);
    });
  }
}

void InterpolateLoop::BeginShutdown() {
  MutexLock lock(request_mu_);
  closing_ = true;
}

void InterpolateLoop::Stop() {
  if (stopped_) return;
  stopped_ = true;
  BeginShutdown();  // in case the caller did not: no call may be asked for on a closed queue
  {
    MutexLock lock(slow_mu_);
    slow_stop_ = true;
  }
  slow_cv_.NotifyAll();
  // The slow lane first: its replies complete on the queues, which must still be open.
  if (slow_lane_.joinable()) slow_lane_.join();
  for (auto& queue : queues_) queue->Shutdown();
  if (loops_.empty()) {  // never started (the server did not come up): drain the queues here
    for (auto& queue : queues_) {
      void* tag = nullptr;
      bool ok = false;
      while (queue->Next(&tag, &ok)) delete static_cast<Call*>(tag);
    }
  }
  for (std::thread& loop : loops_) loop.join();
  loops_.clear();
  // Left behind only if a loop handed a call over after the slow lane had stopped (the server's
  // shutdown should have settled every call by then): released unanswered.
  MutexLock lock(slow_mu_);
  for (Call* call : slow_) delete call;
  slow_.clear();
}

void InterpolateLoop::Request(grpc::ServerCompletionQueue* queue) {
  MutexLock lock(request_mu_);
  if (closing_) return;
  auto* call = new Call(queue);
  service_.RequestInterpolate(&call->context, &call->request, &call->responder, queue, queue, call);
}

void InterpolateLoop::Finish(Call* call, const grpc::Status& status) {
  call->finishing = true;
  if (status.ok()) {
    call->responder.Finish(call->response, status, call);
  } else {
    call->responder.FinishWithError(status, call);
  }
}

void InterpolateLoop::Serve(grpc::ServerCompletionQueue* queue) {
  void* tag = nullptr;
  bool ok = false;
  while (queue->Next(&tag, &ok)) {
    auto* call = static_cast<Call*>(tag);
    // A reply that completed (sent or not), or a call asked for that the shutdown cancelled.
    if (call->finishing || !ok) {
      delete call;
      continue;
    }
    Request(queue);  // the next call, asked for before this one is answered
    if (std::optional<grpc::Status> status =
            service_.AnswerIfReady(call->request, &call->response)) {
      Finish(call, *status);
      continue;
    }
    {
      MutexLock lock(slow_mu_);
      slow_.push_back(call);
    }
    slow_cv_.NotifyOne();
  }
}

void InterpolateLoop::SlowLane() {
  for (;;) {
    Call* call = nullptr;
    {
      MutexLock lock(slow_mu_);
      slow_cv_.Wait(slow_mu_, [this]() REQUIRES(slow_mu_) { return slow_stop_ || !slow_.empty(); });
      if (slow_.empty()) return;  // stopping, and nothing left to answer
      call = slow_.front();
      slow_.pop_front();
    }
    Finish(call, service_.Answer(call->request, &call->response));
  }
}

}  // namespace brdf::daemon
